# at 97bc55c (+ mbm_bench --padding, uncommitted then); shared 2-core machine
python scripts/mbm_bench.py --robot panda --per-class 5 --planners kc-rrtconnect-lazy-native,kc-rrtconnect --padding 0.01 --simplify -o /tmp/prof55/pad-panda
