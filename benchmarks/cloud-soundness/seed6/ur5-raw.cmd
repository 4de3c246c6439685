# at 9db558d, beside development work (no benchmark) on the shared 2-core machine
python scripts/arm_soundness.py --robot ur5 --per-class 10 --edges 36000 --representation hulls --cloud 10000 --graze 0.5 --seed 6
# note: /usr/bin/time was stopped by mistake at 11:34 (the run went on; its resource report is missing)
