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

import sys

from ._arguments import name_wrong_arguments as _name_wrong_arguments
from ._ontime import domains as _domains

available: bool = bool(_domains.available)

if available:
    from ._ontime import UsageError
    from ._ontime.domains import (  # noqa: F401
        Domain, collect, collect_and_fit, feature_names, features, load, map_data, names, predict, run, tamp)
    from ._ontime.domains import generate_kitchen as _generate_kitchen
    from ._ontime.domains import generate_world as _generate_building

    # Arguments of the wrong type raise UsageError naming the parameter (ontime/_arguments.py); before
    # the generators' table below takes the functions.
    _name_wrong_arguments(sys.modules[__name__])
    __all__ = ["Domain", "available", "collect", "collect_and_fit", "feature_names", "features", "generate_world",
               "load", "map_data", "names", "predict", "run", "tamp"]

    _GENERATORS = {
        "navigation": (_generate_building, ("rows", "cols", "room_size", "door_density", "narrow_doors", "narrow_min",
                                            "narrow_max", "wide_min", "wide_max", "empty_rooms", "cluttered_rooms",
                                            "min_boxes", "max_boxes", "skeletons", "seed", "name")),
        "manipulation": (_generate_kitchen, ("tables", "regions", "region_min", "region_max", "targets",
                                             "min_objects", "max_objects", "min_clutter", "max_clutter", "classes",
                                             "seed", "name")),
    }

    def generate_world(output, *, domain: str = "navigation", **options) -> dict:
        """`ontime generate-world`: writes a generated world of `domain` to `output` and returns what it holds
        (the fields of `ontime generate-world --json`). Same options, same seed: the same file.

        domain="navigation": an office building (rows=6, cols=5, room_size=4.0, door_density=0.8,
        narrow_doors=0.2, narrow_min, narrow_max, wide_min, wide_max, empty_rooms, cluttered_rooms, min_boxes,
        max_boxes, skeletons=0, seed=1, name). domain="manipulation": a kitchen table scene with its goal and skeletons
        (tables=2, regions=3, region_min=0.2, region_max=0.35, targets=2, min_objects=6, max_objects=9,
        min_clutter=1, max_clutter=2, classes=["cup", "box", "bottle"], seed=1, name)."""
        if not isinstance(domain, str) or domain not in _GENERATORS:
            raise UsageError(f"domain must be 'navigation' or 'manipulation' (got {domain!r})")
        generate, known = _GENERATORS[domain]
        for option in options:
            if option not in known:
                raise UsageError(f"{option} is not an option of the {domain} generator (its options: "
                                 f"{', '.join(known)})")
        return generate(output, **options)

    # And generate_world's own arguments (an argument too many, a keyword missing).
    _name_wrong_arguments(sys.modules[__name__])
else:
    __all__ = ["available"]

    def __getattr__(name: str):
        raise AttributeError(
            f"ontime.domains.{name}: this build of OnTime has no domains (configure with ONTIME_BUILD_DOMAINS=ON, "
            "which needs OMPL, FCL and KDL)")
