# at e37b8ea (kernel as at c0c5718), niced beside other work on the shared 2-core machine
python scripts/arm_soundness.py --robot panda --per-class 10 --edges 40000 --representation hulls --cloud 10000 --graze 0.5 --seed 4
