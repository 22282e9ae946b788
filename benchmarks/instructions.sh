#!/usr/bin/env bash
# Instructions and floating-point operations executed per call of each core algorithm, beside its
# native time: counted by valgrind's callgrind on the harness crates/robodyn/benches/instructions.rs
# (benchmarks/count_operations.py: each instruction's executions, objdump's name for it, the
# difference between runs of 2N and N calls, so that loading and set-up cancel). This machine's
# virtual CPUs expose no hardware counters, so `perf stat` cannot count them. Needs valgrind
# (apt-get install valgrind) and objdump (binutils).
# Usage: benchmarks/instructions.sh [ROBOT ...]   (default: ur5 panda talos)
set -euo pipefail
cd "$(dirname "$0")/.."
robots=("$@")
[ ${#robots[@]} -eq 0 ] && robots=(ur5 panda talos)
calls=50
binary=$(cargo bench -p robodyn --bench instructions --no-run 2>&1 | sed -n 's/.*Executable .*(\(.*\))/\1/p')
native=$("$binary")

printf "| robot | algorithm | ns per call | instructions per call | flops per call | instructions per flop | instructions per ns |\n"
printf "| --- | --- | --- | --- | --- | --- | --- |\n"
for robot in "${robots[@]}"; do
    for algorithm in $(echo "$native" | awk -F'\t' -v r="$robot" '$1 == r { print $2 }'); do
        ns=$(echo "$native" | awk -F'\t' -v r="$robot" -v a="$algorithm" '$1 == r && $2 == a { print $3 }')
        read -r instructions flops < <(python3 benchmarks/count_operations.py "$binary" "$robot" "$algorithm" "$calls")
        awk -v r="$robot" -v a="$algorithm" -v ns="$ns" -v i="$instructions" -v f="$flops" \
            'BEGIN { printf "| %s | %s | %.0f | %d | %d | %.1f | %.1f |\n", r, a, ns, i, f, i / f, i / ns }'
    done
done
