python scripts/cloud_kc_ablation.py --runs 5 --time 20 --work /tmp/ckc/full > benchmarks/cloud-kc/table.md 2> benchmarks/cloud-kc/table.log
