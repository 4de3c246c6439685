python scripts/arm_soundness.py --robot panda --per-class 5 --edges 5600 --representation hulls --cloud 10000 --graze 0.5 --seed 1
