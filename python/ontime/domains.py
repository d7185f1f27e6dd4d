"""OnTime's TAMP domains (navigation, manipulation) on OMPL, FCL and KDL, when the library was built
with them (ONTIME_BUILD_DOMAINS): load a domain, collect its planner log, run allocators against its
real motion planner.

    nav = ontime.domains.load("navigation", "data/domains/navigation.json")
    records = ontime.domains.collect(nav, trials=100, seed=1)
    problem = ontime.fit(records, step=1.0, deadline=30, skeletons=nav.skeletons)
    print(ontime.domains.run(nav, problem, "dp-rerun", episodes=50)["success_rate"])
"""

from ._ontime import domains as _domains

available: bool = bool(_domains.available)

if available:
    from ._ontime.domains import Domain, collect, load, names, run  # noqa: F401
    __all__ = ["Domain", "available", "collect", "load", "names", "run"]
else:
    __all__ = ["available"]

    def __getattr__(name: str):
        raise AttributeError(
            f"ontime.domains.{name}: this build of OnTime has no domains (configure with ONTIME_BUILD_DOMAINS=ON, "
            "which needs OMPL, FCL and KDL)")
