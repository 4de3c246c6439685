# at 97bc55c (+ mbm_bench --padding, uncommitted then); shared 2-core machine
python scripts/mbm_bench.py --robot ur5 --per-class 3 --planners kc-rrtconnect-lazy-native,kc-rrtconnect --padding 0.01 --simplify -o /tmp/prof55/pad-ur5
