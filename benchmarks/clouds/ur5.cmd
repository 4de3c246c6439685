# at 4cdc166 (kcplan/ clean; its compiled kernel built 00:14:41 from the same sources), VAMP 0.6.4 (f6de6a7) in /work/vamp-venv;
# run on a frozen copy of kcplan (/tmp/kcsnap/s2: kcplan/ and its _core .so; run.py drops the editable finder and puts the copy first),
# because others rebuild the editable install's .so in place while a run has it loaded (two earlier runs died of SIGSEGV that way).
# The same, without the copy: python scripts/cloud_mbm.py --robot ur5 --per-class 3 --vamp-python /work/vamp-venv/bin/python --seed 1 --time 10 --verify-budget 600 --json benchmarks/clouds/ur5.json
.venv/bin/python /tmp/kcsnap/run.py /tmp/kcsnap/s2 scripts/cloud_mbm.py --robot ur5 --per-class 3 --vamp-python /work/vamp-venv/bin/python --seed 1 --time 10 --verify-budget 600 --json benchmarks/clouds/ur5.json
# 249 s wall on the shared 2-core machine (load average 2-4 from other sessions)
