#!/usr/bin/env bash
# Fuzzes every file reader and the quality measure with libFuzzer under ASan + UBSan.
#   scripts/fuzz.sh [SECONDS] [--no-install]   SECONDS per harness (default 30); CI runs 20
# Installs Debian's clang and its libFuzzer runtime (apt-get, unless --no-install), builds
# build-fuzz/ with them, runs each harness on a copy
# of its seed corpus in fuzz/corpus/, and prints the executions and findings of each. Exits 1
# when a harness finds a crash, a leak, a timeout or undefined behaviour; the input that did it
# is left in build-fuzz/findings/.
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-30}
if [[ "${2:-}" != "--no-install" ]]; then
  SUDO=""
  if [[ $(id -u) -ne 0 ]]; then SUDO="sudo"; fi
  export DEBIAN_FRONTEND=noninteractive
  $SUDO apt-get install -y -qq --no-install-recommends clang libclang-rt-14-dev > /dev/null
fi
dir=build-fuzz
cmake -S . -B "$dir" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_C_COMPILER=clang \
  -DCMAKE_CXX_COMPILER=clang++ -DHEXPEEL_FUZZ=ON -DHEXPEEL_BUILD_TESTS=OFF -DHEXPEEL_BUILD_BENCH=OFF > /dev/null
harnesses=(obj off ply mesh msh vtk vtu quality)
targets=()
for h in "${harnesses[@]}"; do
  if [[ $h == quality ]]; then targets+=(fuzz_quality); else targets+=("fuzz_read_$h"); fi
done
cmake --build "$dir" --parallel --target "${targets[@]}"
export ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
mkdir -p "$dir/findings"
failed=0
total=0
for i in "${!harnesses[@]}"; do
  h=${harnesses[$i]}
  work=$(mktemp -d)
  cp fuzz/corpus/"$h"/* "$work"/
  log="$dir/findings/$h.log"
  if "$dir/fuzz/${targets[$i]}" "$work" -max_total_time="$seconds" -max_len=65536 -timeout=10 \
       -rss_limit_mb=2048 -print_final_stats=1 -artifact_prefix="$dir/findings/$h-" > "$log" 2>&1; then
    status=ok
  else
    status=FOUND
    failed=1
  fi
  runs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$log" | grep -o '[0-9]*$' || echo 0)
  total=$((total + ${runs:-0}))
  printf '%-8s %10s executions in %ss  %s\n' "$h" "${runs:-0}" "$seconds" "$status"
  [[ $status == ok ]] || tail -40 "$log"
  rm -rf "$work"
done
echo "total: $total executions, $( ((failed)) && echo 'findings: see build-fuzz/findings/' || echo 'no finding')"
exit $failed
