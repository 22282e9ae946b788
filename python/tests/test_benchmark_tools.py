"""The benchmarks' own arithmetic: how `benchmarks/count_operations.py` counts the floating-point
operations of an instruction (the column `instructions.sh` prints beside instructions)."""

from __future__ import annotations

import importlib.util

import pytest

from conftest import REPOSITORY


@pytest.fixture(scope="module")
def counting():
    spec = importlib.util.spec_from_file_location("count_operations", REPOSITORY / "benchmarks" / "count_operations.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


@pytest.mark.parametrize(
    ("mnemonic", "operands", "operations"),
    [
        ("addsd", "%xmm1,%xmm0", 1),
        ("vmulsd", "%xmm2,%xmm1,%xmm0", 1),
        ("sqrtsd", "%xmm1,%xmm0", 1),
        ("mulpd", "%xmm1,%xmm0", 2),
        ("vsubpd", "%ymm2,%ymm1,%ymm0", 4),
        ("vdivpd", "0x40(%rax),%zmm1,%zmm0", 8),
        ("vfmadd231sd", "%xmm2,%xmm1,%xmm0", 2),
        ("vfnmsub213pd", "%ymm2,%ymm1,%ymm0", 8),
        # not arithmetic on doubles: moves, sign flips, comparisons, integers, singles
        ("vmovapd", "%ymm1,%ymm0", 0),
        ("vxorpd", "%ymm1,%ymm0,%ymm0", 0),
        ("vcmppd", "$0x1,%ymm1,%ymm0,%k1", 0),
        ("vmaxpd", "%ymm1,%ymm0,%ymm0", 0),
        ("add", "$0x8,%rax", 0),
        ("addss", "%xmm1,%xmm0", 0),
    ],
)
def test_an_instruction_counts_one_operation_per_lane(counting, mnemonic, operands, operations):
    assert counting.operations_of(mnemonic, operands) == operations
