"""A CasADi function evaluated straight into preallocated NumPy arrays (CasADi's buffer interface).

Calling a CasADi Function the usual way returns DM matrices, and turning a dense 150×150 Hessian into a
NumPy array costs about 2 ms, as much as evaluating it. Newton's method on the regret needs several such
matrices per iteration, so its functions are evaluated through ``Function.buffer()``, which writes the
outputs into arrays allocated once.
"""

from __future__ import annotations

import casadi as ca
import numpy as np


class BufferedFunction:
    """``f(*args) -> tuple of arrays`` for CasADi expressions ``outputs`` of symbols ``inputs``, outputs dense.

    The returned arrays are overwritten by the next call: copy what must outlive it. Vector outputs come
    back as 1-D arrays, matrices as 2-D (Fortran order), scalars as 0-D arrays. Inputs are flattened
    column by column.
    """

    def __init__(self, name: str, inputs: list, outputs: list):
        self.function = ca.Function(name, inputs, [ca.densify(out) for out in outputs])
        self._buffer, self._trigger = self.function.buffer()
        self._inputs = [np.zeros(self.function.nnz_in(i)) for i in range(self.function.n_in())]
        for i, array in enumerate(self._inputs):
            self._buffer.set_arg(i, memoryview(array))
        self._outputs = []
        for i in range(self.function.n_out()):
            rows, cols = self.function.size_out(i)
            flat = np.zeros(rows * cols)
            self._buffer.set_res(i, memoryview(flat))
            self._outputs.append(flat.reshape((rows, cols), order="F") if cols > 1 else (flat if rows > 1 else flat.reshape(())))

    def __call__(self, *args) -> tuple[np.ndarray, ...]:
        for array, value in zip(self._inputs, args, strict=True):
            array[:] = np.ravel(value, order="F")
        self._trigger()
        return tuple(self._outputs)
