"""Planner names, importable without loading OMPL (for the command line's help)."""

PLANNER_NAMES = (
    "kc-rrtconnect",
    "kc-prm",
    "kc-rrtconnect-discrete",
    "rrtconnect",
    "prm",
    "rrtconnect-fine",
    "prm-fine",
    "rrt",
    "rrtstar",
    "bitstar",
)
