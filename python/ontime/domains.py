"""OnTime's TAMP domains (navigation, manipulation) on OMPL, FCL and KDL, when the library was built
with them (ONTIME_BUILD_DOMAINS): load a domain, collect its planner log, run allocators against its
real motion planner, the whole TAMP loop, maps and generated worlds. Each function is the library
function the command line calls, with its defaults, and returns what its --json prints.

    nav = ontime.domains.load("navigation", "data/domains/navigation.json")
    records = ontime.domains.collect(nav, trials=100, seed=1)
    problem = ontime.fit(records, step=1.0, deadline=30, skeletons=nav.skeletons)
    print(ontime.domains.run(nav, problem, "dp-rerun", episodes=50)["success_rate"])

    building = ontime.domains.load("navigation", "data/domains/building-6x5.json")
    result = ontime.domains.tamp(building, "data/instances/building-6x5-moves.json", "dp-rerun", 60.0,
                                 episodes=10, clock="model")           # as `ontime tamp --json`
"""

from ._ontime import domains as _domains

available: bool = bool(_domains.available)

if available:
    from ._ontime.domains import (  # noqa: F401
        Domain, collect, collect_and_fit, feature_names, features, generate_world, load, map_data, names, predict,
        run, tamp)
    __all__ = ["Domain", "available", "collect", "collect_and_fit", "feature_names", "features", "generate_world",
               "load", "map_data", "names", "predict", "run", "tamp"]
else:
    __all__ = ["available"]

    def __getattr__(name: str):
        raise AttributeError(
            f"ontime.domains.{name}: this build of OnTime has no domains (configure with ONTIME_BUILD_DOMAINS=ON, "
            "which needs OMPL, FCL and KDL)")
