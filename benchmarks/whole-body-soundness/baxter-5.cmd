# at 8121d53 (the arm certifier unchanged since d0656dd), the machine otherwise quiet
python scripts/arm_soundness.py --robot baxter --scenarios benchmarks/whole-body/baxter/*.yaml --edges 2500 --representation hulls --graze 0.5 --seed 5
