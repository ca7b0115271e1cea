"""Calling a CasADi function on NumPy arrays without conversions (:class:`BufferedFunction`)."""

from __future__ import annotations

import casadi as ca
import numpy as np


class BufferedFunction:
    """Calls a CasADi function on NumPy arrays through CasADi's zero-copy ``Function.buffer()`` interface.

    A plain call converts every input and output between NumPy and CasADi's DM, which for the planner's small
    per-solve functions costs more than evaluating them; the buffer reads and writes preallocated arrays in
    place. Inputs must be dense and are copied into the buffer; outputs are returned as fresh
    dense arrays of each output's shape (structural zeros filled in).
    """

    def __init__(self, function: ca.Function):
        self.function = function
        for i in range(function.n_in()):
            if not function.sparsity_in(i).is_dense():
                raise ValueError(f"BufferedFunction needs dense inputs; input {function.name_in(i)!r} is sparse")
        self._inputs = [np.zeros(function.nnz_in(i)) for i in range(function.n_in())]
        self._outputs = [np.zeros(function.nnz_out(i)) for i in range(function.n_out())]
        self._shapes = [function.size_out(i) for i in range(function.n_out())]
        self._entries = []  # (rows, columns) of each sparse output's nonzeros; None when dense
        for i in range(function.n_out()):
            sparsity = function.sparsity_out(i)
            self._entries.append(None if sparsity.is_dense() else tuple(np.array(v) for v in sparsity.get_triplet()))
        # a dense output with one row or column needs no reordering: copied as it is, then given its shape
        self._vectors = [entries is None and min(shape) == 1 for entries, shape in zip(self._entries, self._shapes)]
        self._buffer, self._evaluate = function.buffer()
        for i, array in enumerate(self._inputs):
            self._buffer.set_arg(i, memoryview(array))
        for i, array in enumerate(self._outputs):
            self._buffer.set_res(i, memoryview(array))

    def vector(self, *args) -> np.ndarray:
        """The first output's entries in column-major order (a fresh array; dense outputs only): a call without the
        list of outputs and their reshaping, for a function whose first output is a vector."""
        for array, value in zip(self._inputs, args):
            array[:] = value.ravel(order="F") if getattr(value, "ndim", 0) > 1 else value
        self._evaluate()
        if self._buffer.ret() != 0:
            raise RuntimeError(f"evaluating {self.function.name()} failed")
        return self._outputs[0].copy()

    def __call__(self, *args) -> list[np.ndarray]:
        for array, value in zip(self._inputs, args):
            # vectors and scalars as they are (np.ravel costs more than the copy); matrices column by column
            array[:] = value.ravel(order="F") if getattr(value, "ndim", 0) > 1 else value
        self._evaluate()
        if self._buffer.ret() != 0:
            raise RuntimeError(f"evaluating {self.function.name()} failed")
        results = []
        for values, shape, entries, vector in zip(self._outputs, self._shapes, self._entries, self._vectors):
            if vector:
                results.append(values.copy().reshape(shape))
            elif entries is None:
                results.append(values.reshape(shape, order="F").copy())
            else:
                dense = np.zeros(shape)
                dense[entries] = values
                results.append(dense)
        return results
