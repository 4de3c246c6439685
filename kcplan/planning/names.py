"""Planner names, importable without loading OMPL (for the command line's help)."""

PLANNER_NAMES = (
    "kc-rrtconnect",
    "kc-prm",
    "ca-rrtconnect",
    "ca-prm",
    "kc-rrtconnect-paper",
    "kc-prm-paper",
    "kc-rrtconnect-discrete",
    "rrtconnect",
    "prm",
    "rrtconnect-fine",
    "prm-fine",
    "rrt",
    "rrtstar",
    "bitstar",
)
