# run before --balls existed, when kcplan.arm.verify.ArmMeshChecker itself put every point of a
# cloud in its own fcl.Sphere (before commit 4a2dbe3); the same re-check now:
python scripts/arm_soundness.py --robot panda --edges 420 --representation hulls --per-class 2 --cloud 10000 --graze 0.5 --seed 1 --spacing 0.01 --balls
