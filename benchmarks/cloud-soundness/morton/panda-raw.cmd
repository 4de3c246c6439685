# at 082c4d3 (the Morton tree), niced beside other work on the shared 2-core machine
python scripts/arm_soundness.py --robot panda --per-class 5 --edges 5600 --representation hulls --cloud 10000 --graze 0.5 --seed 2
