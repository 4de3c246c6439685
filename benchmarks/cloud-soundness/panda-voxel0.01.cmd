python scripts/arm_soundness.py --robot panda --per-class 5 --edges 2800 --representation hulls --cloud 10000 --graze 0.5 --seed 1 --spacing 0.01
