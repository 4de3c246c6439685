# on the kernel of f801ab2 with benchmarks/sphere-layers/sphere-layers.patch applied (16 balls a hull, on):
# the layers' pre-tests in every query of the certifier; not counted towards RESULTS 31.2 (a kernel not shipped)
python scripts/arm_soundness.py --robot baxter --scenarios benchmarks/whole-body/baxter/*.yaml --edges 3000 --representation hulls --graze 0.5 --seed 8
