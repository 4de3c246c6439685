# at cd02ff6 (kernel as at c0c5718), beside the Panda's run on the shared 2-core machine
python scripts/arm_soundness.py --robot ur5 --per-class 10 --edges 12000 --representation hulls --cloud 10000 --graze 0.5 --seed 5
