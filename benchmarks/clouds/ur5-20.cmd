# at 5aeefc1 (kernel as at c0c5718), VAMP 0.6.4 in /work/vamp-venv; shared 2-core machine, nothing else running
python scripts/cloud_mbm.py --robot ur5 --per-class 20 --planner kc-rrtconnect-lazy-native --vamp-python /work/vamp-venv/bin/python --json benchmarks/clouds/ur5-20.json
