python scripts/arm_soundness.py --robot panda --edges 420 --representation hulls --per-class 2 --cloud 10000 --graze 0.5 --seed 1
