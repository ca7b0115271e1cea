"""Where a person switches from the fast initial sub-movement to the corrective one (paper II-B, Fig. 2).

:class:`TransitionModel` is a Gaussian-process regression (scikit-learn) of the transition distance T (m),
the distance from the goal of the peak perpendicular dispersion, on the goal distance normalised by the
arm length, D/L, and the goal width w (m):

    T(D/L, w) ~ GP(0, c · Matern_5/2(per-input length scales) + white noise)

on standardised inputs and target (each to zero mean, unit variance over the training data). The kernel's
hyperparameters (c, the two length scales, the noise level) are fitted by maximising the log marginal
likelihood. A saved model is JSON: those hyperparameters plus the training data; loading refits the GP
with the hyperparameters held, which reproduces the posterior exactly (no pickle).
"""

from __future__ import annotations

import json
import warnings
from pathlib import Path

import numpy as np

from comanip.arguments import as_positive, as_positive_array
from comanip.multicomponent.transition_csv import (
    REQUIRED_COLUMNS,
    check_transition_columns,
    read_transition_csv,
    shipped_dataset_path,
)
from comanip.multicomponent.transition_data import ARM_LENGTH

MATERN_NU = 2.5
"""Matern smoothness: twice differentiable predictions, less prone than RBF to ringing between points."""

_SHIPPED = object()


class ExtrapolationWarning(UserWarning):
    """A prediction was asked for outside the range of the training data."""


class TransitionModel:
    """GP model of the transition distance from the goal, T (m), on (D/L, w).

    >>> model = comanip.TransitionModel()                 # fitted on the shipped (simulated) dataset
    >>> mean, std = model.predict(distance=0.35, width=0.02)          # metres in, metres out
    >>> lab = comanip.TransitionModel("my_lab.csv", arm_length=0.65)  # your own measurements
    >>> lab.save("lab_model.json"); comanip.TransitionModel.load("lab_model.json")

    Args:
        data: what to fit on: a transition CSV path, a mapping of its columns, or a tuple of arrays
            (D/L (N,), w (N,) m, T (N,) m); the shipped dataset when omitted; None leaves the model unfitted.
        arm_length: L (m) that turns a goal distance in metres into D/L in :meth:`predict`.
        n_restarts: extra random starts of the marginal-likelihood optimiser.
        random_state: seed of those restarts (fits are reproducible).
    """

    def __init__(self, data=_SHIPPED, arm_length: float = ARM_LENGTH, n_restarts: int = 4, random_state: int = 0):
        self.arm_length = as_positive("arm_length", arm_length, "m")
        self.n_restarts = int(n_restarts)
        self.random_state = int(random_state)
        self._gp = None
        if data is _SHIPPED:
            data = shipped_dataset_path()
        if data is not None:
            self.fit(data)

    # ---- fitting -------------------------------------------------------------------------------------------
    def fit(self, data) -> "TransitionModel":
        """Fit on a transition CSV path, a mapping of its columns, or arrays (D/L, w (m), T (m)); returns self."""
        columns = _as_columns(data)
        if len(columns["width_m"]) < 3:
            raise ValueError(f"need at least 3 rows (conditions) to fit a transition model, got {len(columns['width_m'])}")
        self._fit_columns(columns, hyperparameters=None)
        return self

    def _fit_columns(self, columns: dict, hyperparameters: dict | None) -> None:
        # scikit-learn is imported here, not at the top: it takes over a second to import, and `import comanip`
        # (every CLI call, every worker process) should not pay that unless a transition model is fitted
        from sklearn.exceptions import ConvergenceWarning
        from sklearn.gaussian_process import GaussianProcessRegressor
        from sklearn.preprocessing import StandardScaler

        self.training_data = columns
        X = np.column_stack([columns["distance_over_arm_length"], columns["width_m"]])
        y = columns["transition_distance_m"][:, None]
        self._x_scaler = StandardScaler().fit(X)
        self._y_scaler = StandardScaler().fit(y)
        fixed = hyperparameters is not None
        gp = GaussianProcessRegressor(kernel=_kernel(hyperparameters), optimizer=None if fixed else "fmin_l_bfgs_b",
                                      n_restarts_optimizer=0 if fixed else self.n_restarts,
                                      random_state=self.random_state, normalize_y=False)
        with warnings.catch_warnings():
            # On standardised data a bound reached is itself the answer, not a failed fit: a length scale at its
            # upper bound (1000 data standard deviations) means that input has no detectable effect; the noise
            # at its lower bound (1e-6 of the variance) means the data are practically exact.
            warnings.simplefilter("ignore", ConvergenceWarning)
            self._gp = gp.fit(self._x_scaler.transform(X), self._y_scaler.transform(y).ravel())

    @property
    def is_fitted(self) -> bool:
        return self._gp is not None

    @property
    def hyperparameters(self) -> dict:
        """Fitted kernel: signal variance c and noise level (in standardised target units), length scales
        (in standardised input units, [D/L, w])."""
        self._require_fitted()
        kernel = self._gp.kernel_
        return {"signal_variance": float(kernel.k1.k1.constant_value),
                "length_scales": np.atleast_1d(kernel.k1.k2.length_scale).astype(float).tolist(),
                "noise_level": float(kernel.k2.noise_level), "matern_nu": MATERN_NU}

    @property
    def noise_std(self) -> float:
        """Fitted observation-noise standard deviation of T (m): the scatter of the data about the model."""
        return float(np.sqrt(self.hyperparameters["noise_level"]) * self._y_scaler.scale_[0])

    @property
    def kernel_description(self) -> str:
        """The fitted kernel in words, with the length scales converted to input units."""
        p = self.hyperparameters
        scales = np.array(p["length_scales"]) * self._x_scaler.scale_
        return (f"{p['signal_variance']:.3g} · Matern(nu={MATERN_NU}, length scales D/L {scales[0]:.3g}, "
                f"w {scales[1]:.4g} m) + white noise (std {1e3 * self.noise_std:.2f} mm)")

    @property
    def data_range(self) -> dict:
        """Range of the training inputs: {"distance_over_arm_length": (min, max), "width_m": (min, max)}."""
        self._require_fitted()
        return {name: (float(self.training_data[name].min()), float(self.training_data[name].max()))
                for name in REQUIRED_COLUMNS[:2]}

    # ---- prediction ----------------------------------------------------------------------------------------
    def predict(self, distance, width) -> tuple:
        """Transition distance from the goal for a reach of goal distance D (m) and goal width w (m).

        Args:
            distance: D, m (> 0), scalar or array; divided by ``arm_length`` to give D/L.
            width: w, m (> 0), scalar or array broadcastable with distance.

        Returns:
            (mean, std) of T in m, shaped like the broadcast inputs (floats for scalar inputs). std is the
            model's uncertainty about T (the posterior of the GP's latent function, without the observation
            noise, see :attr:`noise_std`). Inputs outside the data's range give an :class:`ExtrapolationWarning`.
        """
        distance = as_positive_array("distance", distance, "goal distance, m")
        return self._predict(distance / self.arm_length, as_positive_array("width", width, "goal width, m"))

    def predict_normalised(self, distance_over_arm_length, width) -> tuple:
        """As :meth:`predict`, with the goal distance given as D/L (dimensionless)."""
        ratio = as_positive_array("distance_over_arm_length", distance_over_arm_length, "goal distance / arm length")
        return self._predict(ratio, as_positive_array("width", width, "goal width, m"))

    def _predict(self, ratio: np.ndarray, width: np.ndarray) -> tuple:
        self._require_fitted()
        try:
            ratio, width = np.broadcast_arrays(ratio, width)
        except ValueError:
            raise ValueError(f"distance and width must broadcast together, got shapes {ratio.shape} and {width.shape}") from None
        self._warn_if_extrapolating(ratio, width)
        mean, variance = self.posterior(ratio.ravel(), width.ravel(), full_covariance=False)
        std = np.sqrt(variance)
        if ratio.ndim == 0:
            return float(mean[0]), float(std[0])
        return mean.reshape(ratio.shape), std.reshape(ratio.shape)

    def posterior(self, distance_over_arm_length: np.ndarray, width: np.ndarray, full_covariance: bool = True):
        """Latent posterior of T at points (D/L (K,), w (K,) m): mean (K,) m and covariance (K, K) m²
        (or variance (K,) m² when full_covariance is False). No input checks or warnings."""
        self._require_fitted()
        X = self._x_scaler.transform(np.column_stack([distance_over_arm_length, width]))
        scale = self._y_scaler.scale_[0]
        noise = self.hyperparameters["noise_level"]
        if full_covariance:
            mean, cov = self._gp.predict(X, return_cov=True)
            latent = (cov - noise * np.eye(len(X))) * scale**2
        else:
            mean, std = self._gp.predict(X, return_std=True)
            latent = np.maximum(std**2 - noise, 0.0) * scale**2
        return self._y_scaler.inverse_transform(mean[:, None]).ravel(), latent

    # ---- persistence ---------------------------------------------------------------------------------------
    def to_dict(self) -> dict:
        """JSON-ready: kernel hyperparameters, arm length and the training data."""
        self._require_fitted()
        return {"kind": "comanip.TransitionModel", "version": 1, "arm_length_m": self.arm_length,
                "kernel": self.hyperparameters, "kernel_description": self.kernel_description,
                "training_data": {k: v.tolist() for k, v in self.training_data.items()}}

    def save(self, path: str | Path) -> Path:
        path = Path(path)
        path.write_text(json.dumps(self.to_dict(), indent=1))
        return path

    @classmethod
    def load(cls, path: str | Path) -> "TransitionModel":
        """A model saved by :meth:`save`; the posterior equals the saved model's."""
        path = Path(path)
        try:
            saved = json.loads(path.read_text())
        except (OSError, json.JSONDecodeError) as error:
            raise ValueError(f"cannot read a transition model from {str(path)!r}: {error}") from None
        if not isinstance(saved, dict) or saved.get("kind") != "comanip.TransitionModel":
            raise ValueError(f"{path} is not a saved comanip.TransitionModel (no 'kind': 'comanip.TransitionModel')")
        model = cls(data=None, arm_length=saved["arm_length_m"])
        model._fit_columns(check_transition_columns(saved["training_data"], source=str(path)), saved["kernel"])
        return model

    # ---- helpers -------------------------------------------------------------------------------------------
    def _require_fitted(self):
        if self._gp is None:
            raise ValueError("the transition model is not fitted: call fit(csv_or_arrays) first")

    def _warn_if_extrapolating(self, ratio: np.ndarray, width: np.ndarray) -> None:
        (r_lo, r_hi), (w_lo, w_hi) = self.data_range.values()
        outside = []
        if ratio.min() < r_lo or ratio.max() > r_hi:
            outside.append(f"D/L from {ratio.min():.3g} to {ratio.max():.3g} (goal distance "
                           f"{ratio.min() * self.arm_length:.3g}–{ratio.max() * self.arm_length:.3g} m at L = "
                           f"{self.arm_length} m) leaves the data's range [{r_lo:.3g}, {r_hi:.3g}]")
        if width.min() < w_lo or width.max() > w_hi:
            outside.append(f"w from {width.min():.3g} to {width.max():.3g} m leaves the data's range [{w_lo:.3g}, {w_hi:.3g}] m")
        if outside:
            warnings.warn("transition model extrapolates: " + "; ".join(outside) + ". The std grows away from the data, and far "
                          "beyond it the mean reverts toward the data's average transition distance "
                          f"({self.training_data['transition_distance_m'].mean():.3g} m).",
                          ExtrapolationWarning, stacklevel=4)  # the caller of predict*


def _kernel(hyperparameters: dict | None):
    """c · Matern(per-input length scales) + white noise; free when hyperparameters is None, else held."""
    from sklearn.gaussian_process.kernels import ConstantKernel, Matern, WhiteKernel

    if hyperparameters is None:
        return (ConstantKernel(1.0, (1e-3, 1e4)) * Matern([1.0, 1.0], (1e-2, 1e3), nu=MATERN_NU)
                + WhiteKernel(0.1, (1e-6, 1e1)))
    p = hyperparameters
    return (ConstantKernel(p["signal_variance"], "fixed") * Matern(p["length_scales"], "fixed", nu=p.get("matern_nu", MATERN_NU))
            + WhiteKernel(p["noise_level"], "fixed"))


def _as_columns(data) -> dict[str, np.ndarray]:
    if isinstance(data, (str, Path)):
        return read_transition_csv(data)
    if isinstance(data, dict):
        return check_transition_columns(data)
    if isinstance(data, (tuple, list)) and len(data) == 3:
        return check_transition_columns(dict(zip(REQUIRED_COLUMNS, data)))
    raise ValueError("data must be a transition CSV path, a mapping with columns "
                     f"{list(REQUIRED_COLUMNS)}, or a tuple (D/L, w in m, T in m) of equal-length arrays; "
                     f"got {type(data).__name__}")

