# at d0656dd, beside the UR5 cloud soundness runs and the PR2 run on the shared 2-core machine
python scripts/arm_soundness.py --robot baxter --scenarios benchmarks/whole-body/baxter/*.yaml --edges 2000 --representation hulls --graze 0.5 --seed 1
