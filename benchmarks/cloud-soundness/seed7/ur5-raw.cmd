# at c9b5382, beside seed 6, the whole-body soundness and bench runs and development work (no benchmark) on the shared 2-core machine
python scripts/arm_soundness.py --robot ur5 --per-class 10 --edges 37000 --representation hulls --cloud 10000 --graze 0.5 --seed 7
