python scripts/arm_soundness.py --robot ur5 --edges 1400 --representation hulls --per-class 2 --cloud 10000 --graze 0.5 --seed 1 --spacing 0.01
