"""Scalar functions that keep a loop vectorisable.

Numba compiles ``math.sqrt`` to a call of the C library's ``sqrt`` (which may
set ``errno``), and LLVM does not vectorise a loop with such a call. The
LLVM intrinsic below is the same IEEE-754 square root (correctly rounded,
so the same bits), which SIMD loops compute with one vector instruction.
"""

from __future__ import annotations

from llvmlite import ir
from numba import types
from numba.extending import intrinsic


@intrinsic
def sqrt(typingctx, x):
    """IEEE square root of a float64 (LLVM ``llvm.sqrt.f64``; NaN below 0)."""
    sig = types.float64(types.float64)

    def codegen(context, builder, signature, args):
        fn = builder.module.declare_intrinsic("llvm.sqrt", [ir.DoubleType()])
        return builder.call(fn, args)

    return sig, codegen
