# at 84f8e40 (the arm certifier unchanged since d0656dd), beside a clean-clone CI run on the shared 2-core machine
python scripts/arm_soundness.py --robot baxter --scenarios benchmarks/whole-body/baxter/*.yaml --edges 2500 --representation hulls --graze 0.5 --seed 2
