#!/usr/bin/env bash
# Instructions executed per call of each core algorithm, beside its native time: counted by
# valgrind's callgrind on the harness crates/robodyn/benches/instructions.rs, as the difference
# between runs of 2N and N calls (loading and set-up cancel). This machine's virtual CPUs expose no
# hardware counters, so `perf stat` cannot count them. Needs valgrind (apt-get install valgrind).
# Usage: benchmarks/instructions.sh [ROBOT ...]   (default: ur5 panda talos)
set -euo pipefail
cd "$(dirname "$0")/.."
robots=("$@")
[ ${#robots[@]} -eq 0 ] && robots=(ur5 panda talos)
calls=50
binary=$(cargo bench -p robodyn --bench instructions --no-run 2>&1 | sed -n 's/.*Executable .*(\(.*\))/\1/p')
native=$("$binary")

# instructions executed by ROBOT ALGORITHM CALLS
count() {
    valgrind --tool=callgrind --callgrind-out-file=/dev/null "$binary" "$1" "$2" "$3" 2>&1 |
        sed -n 's/.*Collected : \([0-9]*\).*/\1/p'
}

printf "| robot | algorithm | ns per call | instructions per call | instructions per ns |\n"
printf "| --- | --- | --- | --- | --- |\n"
for robot in "${robots[@]}"; do
    for algorithm in $(echo "$native" | awk -F'\t' -v r="$robot" '$1 == r { print $2 }'); do
        ns=$(echo "$native" | awk -F'\t' -v r="$robot" -v a="$algorithm" '$1 == r && $2 == a { print $3 }')
        once=$(count "$robot" "$algorithm" "$calls")
        twice=$(count "$robot" "$algorithm" $((2 * calls)))
        awk -v r="$robot" -v a="$algorithm" -v ns="$ns" -v i="$(((twice - once) / calls))" \
            'BEGIN { printf "| %s | %s | %.0f | %d | %.1f |\n", r, a, ns, i, i / ns }'
    done
done
