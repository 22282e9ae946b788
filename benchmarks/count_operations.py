"""Instructions and floating-point operations executed per call of one algorithm, counted by
valgrind's callgrind on the harness of `instructions.sh` (crates/robodyn/benches/instructions.rs).

Callgrind counts how often each instruction of the harness ran (`--dump-instr=yes`); objdump
names each instruction, and an arithmetic one on doubles counts one operation per lane it
computes (`addsd`, `mulsd`, `subsd`, `divsd`, `sqrtsd`: 1; the same on `xmm`, `ymm`, `zmm`
registers with `pd`: 2, 4, 8; a fused multiply-add twice that). Comparisons, minima, sign flips
and moves are not operations. Two runs, of N and 2N calls, give one call's counts by difference,
so loading the model and the set-up cancel. This machine's virtual CPUs expose no hardware
counters, so `perf stat` cannot count either.

Usage: python3 benchmarks/count_operations.py HARNESS ROBOT ALGORITHM [CALLS]
prints: instructions per call, floating-point operations per call.
"""

from __future__ import annotations

import re
import subprocess
import sys
import tempfile
from pathlib import Path

#: Arithmetic on doubles, scalar (sd) or packed (pd); a fused multiply-add is two operations.
ARITHMETIC = re.compile(r"^v?(add|sub|mul|div|sqrt)(?P<kind>sd|pd)$")
FUSED = re.compile(r"^vfn?m(add|sub)(132|213|231)(?P<kind>sd|pd)$")
LANES = {"xmm": 2, "ymm": 4, "zmm": 8}


def operations_of(mnemonic: str, operands: str) -> int:
    """Floating-point operations of one instruction (0 for any other)."""
    match = ARITHMETIC.match(mnemonic) or FUSED.match(mnemonic)
    if not match:
        return 0
    lanes = 1
    if match["kind"] == "pd":
        # the widest register named is the width the instruction computes
        lanes = max((n for register, n in LANES.items() if register in operands), default=2)
    return lanes * (2 if FUSED.match(mnemonic) else 1)


def operations_by_address(binary: str) -> dict[int, int]:
    """The floating-point operations of each arithmetic instruction of `binary`, by address."""
    listing = subprocess.run(
        ["objdump", "-d", "--no-show-raw-insn", binary], capture_output=True, text=True, check=True
    ).stdout
    operations = {}
    for line in listing.splitlines():
        # "   82990:\tvmulpd %ymm1,%ymm2,%ymm3"
        parts = line.split("\t")
        if len(parts) < 2 or not parts[0].strip().endswith(":"):
            continue
        fields = parts[1].split(None, 1)
        if not fields:
            continue
        count = operations_of(fields[0], fields[1] if len(fields) > 1 else "")
        if count:
            operations[int(parts[0].strip()[:-1], 16)] = count
    return operations


def executed(binary: str, operations: dict[int, int], robot: str, algorithm: str, calls: int) -> tuple[int, int]:
    """Instructions and floating-point operations (`operations` by address) executed by `calls`
    calls, loading and set-up included (callgrind)."""
    with tempfile.TemporaryDirectory() as folder:
        out = Path(folder) / "callgrind.out"
        subprocess.run(
            ["valgrind", "--tool=callgrind", "--dump-instr=yes", "--compress-pos=no",
             "--compress-strings=no", f"--callgrind-out-file={out}", binary, robot, algorithm,
             str(calls)],
            capture_output=True, check=True,
        )
        instructions = flops = 0
        ours = after_call = False
        for line in out.read_text().splitlines():
            if line.startswith("ob="):
                ours = Path(line[3:]).resolve() == Path(binary).resolve()
            elif line.startswith("calls="):
                # the next cost line is the called function's inclusive cost, not this one's
                after_call = True
            elif line.startswith("0x"):
                if after_call:
                    after_call = False
                    continue
                address, _line, count = line.split()
                instructions += int(count)
                if ours:
                    flops += int(count) * operations.get(int(address, 16), 0)
        return instructions, flops


def main() -> None:
    binary, robot, algorithm = sys.argv[1:4]
    calls = int(sys.argv[4]) if len(sys.argv) > 4 else 50
    operations = operations_by_address(binary)
    once, twice = (executed(binary, operations, robot, algorithm, n) for n in (calls, 2 * calls))
    print(*((b - a) // calls for a, b in zip(once, twice)))


if __name__ == "__main__":
    main()
