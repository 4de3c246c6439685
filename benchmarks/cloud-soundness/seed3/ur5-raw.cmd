# at bc16b1d (kernel as at c0c5718), niced beside the other robot's run on the shared 2-core machine
python scripts/arm_soundness.py --robot ur5 --per-class 10 --edges 12000 --representation hulls --cloud 10000 --graze 0.5 --seed 3
