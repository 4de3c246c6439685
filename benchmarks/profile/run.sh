# RESULTS 34.2: where a compiled lazy plan's time goes (perf's call graphs). The kernel
# built with its symbols kept: pip install -e . -Ccmake.define.KCPLAN_NOSTRIP=ON
set -e
perf record -F 3000 --call-graph dwarf,16384 -o /tmp/prims.data \
  python benchmarks/profile/plan_loop.py --prims --seeds 6
perf report -i /tmp/prims.data --children --sort sym --stdio -g none | grep -v "^$" | head -160 | cut -c1-220 > benchmarks/profile/prims.txt
perf record -F 2000 --call-graph dwarf,16384 -o /tmp/cloud.data \
  python benchmarks/profile/plan_loop.py --seeds 3
perf report -i /tmp/cloud.data --children --sort sym --stdio -g none | grep -v "^$" | head -160 | cut -c1-220 > benchmarks/profile/cloud.txt
