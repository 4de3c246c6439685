# at 90f31ee (the arm certifier unchanged since d0656dd), beside test runs and kernel builds on the other core
python scripts/arm_soundness.py --robot baxter --scenarios benchmarks/whole-body/baxter/*.yaml --edges 3000 --representation hulls --graze 0.5 --seed 7
