# at 1916724, beside the UR5 cloud soundness run and the whole-body bench on the shared 2-core machine
python scripts/arm_soundness.py --robot pr2 --scenarios benchmarks/whole-body/pr2/*.yaml --edges 20000 --representation hulls --graze 0.5 --seed 1
