python scripts/arm_soundness.py --robot ur5 --per-class 3 --edges 1050 --representation hulls --cloud 10000 --graze 0.5 --seed 1
