# at 76401c5 (the arm certifier unchanged since d0656dd), the machine otherwise quiet
python scripts/arm_soundness.py --robot baxter --scenarios benchmarks/whole-body/baxter/*.yaml --edges 2000 --representation hulls --graze 0.5 --seed 6
