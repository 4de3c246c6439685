# at f801ab2 (the arm certifier unchanged since d0656dd), the machine otherwise quiet but for short test runs
python scripts/arm_soundness.py --robot baxter --scenarios benchmarks/whole-body/baxter/*.yaml --edges 3000 --representation hulls --graze 0.5 --seed 9
