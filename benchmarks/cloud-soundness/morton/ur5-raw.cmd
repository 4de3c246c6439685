# at d4ce613 (the Morton tree; per-link padding unused), niced beside other work on the shared 2-core machine
python scripts/arm_soundness.py --robot ur5 --per-class 3 --edges 2100 --representation hulls --cloud 10000 --graze 0.5 --seed 2
