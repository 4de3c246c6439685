# at ad03aab, quiet machine: the UR5's cage problems of RESULTS 26.4 with seeds 1-5 (RESULTS 26.5)
for s in 1 2 3 4 5; do
  python scripts/mbm_bench.py --robot ur5 --classes cage --per-class 5 \
    --planners kc-rrtconnect-lazy-native,kc-rrtconnect-lazy,rrtconnect-32-native,rrtconnect-32 \
    --time 10 --seed $s -o /tmp/cage/s$s > benchmarks/native/ur5-cage-seeds/seed$s.md
done
