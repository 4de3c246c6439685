#!/bin/sh
# First use of four whole-body robots of example-robot-data (issue 57): `kcplan robot info`
# with an empty cache (hulls and the self pairs' proofs computed), each into NAME.txt with
# its wall time. Run from the checkout: sh benchmarks/whole-body/first-use/run.sh
set -e
R=$(python -c "from kcplan.arm.examples import example_folder; print(example_folder())")
out=benchmarks/whole-body/first-use
arm() { for i in 1 2 3 4 5 6 7; do printf ' arm_%s_%s_joint' "$1" "$i"; done; }
run() {
  name=$1; shift
  cache=$(mktemp -d)
  start=$(date +%s.%N)
  KCPLAN_CACHE_DIR=$cache kcplan robot info "$@" > $out/$name.txt 2>&1
  end=$(date +%s.%N)
  echo "$name: $(echo "$end - $start" | bc) s" | tee -a $out/times.txt
  rm -rf "$cache"
}
: > $out/times.txt
run pr2 $R/pr2_description/urdf/pr2.urdf --srdf $R/pr2_description/srdf/pr2.srdf \
  --group whole_body --base -3 3 -2 2
run tiago $R/tiago_description/robots/tiago.urdf --base -3 3 -2 2 \
  --joints base/x base/y base/theta torso_lift_joint $(for i in 1 2 3 4 5 6 7; do printf ' arm_%s_joint' $i; done)
run tiago_dual $R/tiago_description/robots/tiago_dual.urdf --base -3 3 -2 2 \
  --joints base/x base/y base/theta torso_lift_joint $(arm left) $(arm right)
run baxter $R/baxter_description/urdf/baxter.urdf \
  --srdf $R/baxter_description/srdf/baxter_manipulation.srdf \
  --joints $(for s in left right; do for j in s0 s1 e0 e1 w0 w1 w2; do printf ' %s_%s' $s $j; done; done)
