r"""Thrust allocation for R/V Gunnerus' two aft azimuth pods, and the envs' action scaling.

Force model (seed 001 eq. 19-20): a pod at ``(x_i, y_i)`` with thrust ``T_i >= 0`` and azimuth
``a_i`` gives the body-frame force and moment

.. math:: \tau_i = T_i \, [\cos a_i,\; \sin a_i,\; -y_i \cos a_i + x_i \sin a_i]^T .

Allocation (:func:`allocate_force_moment`): both pods get the same thrust ``T`` and azimuth
``a`` (the way the Gunnerus envs drive them). With ``c = T cos a`` and ``s = T sin a``::

    X = 2 c,      N = (x_1 + x_2) s - (y_1 + y_2) c

(the ``y`` terms cancel for the symmetric pods, ``y_2 = -y_1``: ``N = 2 x_p s``), so
``c = X / 2``, ``s = (N + (y_1 + y_2) X / 2) / (x_1 + x_2)``, ``T = hypot(c, s)`` and
``a = atan2(s, c)``. The sway force ``Y = 2 s`` follows and is not controlled. The pods sit
aft (``x_p = -15.56 m``), so a positive azimuth gives a negative (port) yaw moment.

Limits: ``0 <= T <= T_max`` and ``|a| <= a_max`` with ``a_max <= 90 deg`` (no astern thrust:
a negative ``X`` cannot be produced). When ``(c, s)`` is outside that sector the choice is

* ``priority="yaw"`` (default): keep the side component ``s`` (the yaw moment) as far as
  ``|s| <= T_max sin(a_max)`` allows, then take the feasible ``c`` closest to the request
  (a small ``X`` request with a large ``N`` gets *more* surge force than asked, the only
  way to make the moment with an azimuth limit);
* ``priority="surge"``: keep ``c`` (clipped to ``[0, T_max]``), then the feasible ``s``
  closest to the request.

Action scaling (:class:`PodCommand`): the Gunnerus envs map a normalised action
``a in [-1, 1]^m`` to the model input ``u = [T_1, T_2, alpha_1, alpha_2] = u0 + B a``
(``shipgym.envs.tasks``)::

    heading env (RVGHeading):            u0 = [T_s, T_s, 0, 0],  alpha = a_max a_0
    speed env (RVGSpeed):                u0 = [T_b/2, T_b/2, 0, 0], T = T_b/2 (1 + a_0)
    path / target envs (RVGPathFollowing, RVGTargetTracking):
                                         alpha = a_max a_0,      T = T_b/2 (1 + a_1)

with ``a_max = 35 deg``, the bollard thrust ``T_b = 121.7 kN`` and the service thrust
``T_s = 25 kN``. The inverse is ``a_alpha = alpha / a_max`` and ``a_T = 2 T / T_b - 1``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

import numpy as np
import numpy.typing as npt

from controllers._angles import finite, positive

__all__ = [
    "BOLLARD_THRUST",
    "ENV_MAX_AZIMUTH",
    "POD_X",
    "POD_Y",
    "PodCommand",
    "allocate_force_moment",
    "azimuth_to_action",
    "pod_env_actions",
    "pod_forces",
    "thrust_to_action",
]

#: Pod positions [m] relative to the CG, port pod first (seed 001 Table 2).
POD_X: tuple[float, float] = (-15.56, -15.56)
POD_Y: tuple[float, float] = (-2.7, 2.7)
#: Per-pod thrust at zero speed [N] (121.7 kN, Kongsberg pod at 200 rpm).
BOLLARD_THRUST = 121.7e3
#: Azimuth range of the Gunnerus envs' actions [rad] (35 deg).
ENV_MAX_AZIMUTH = math.radians(35.0)

EnvName = Literal["heading", "speed", "path", "target"]
_ENVS = ("heading", "speed", "path", "target")


def _pair(name: str, value: float | tuple[float, float]) -> tuple[float, float]:
    if isinstance(value, int | float | np.floating | np.integer):
        v = finite(name, value)
        return (v, v)
    try:
        a, b = value
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a number or a pair of numbers, got {value!r}") from None
    return (finite(f"{name}[0]", a), finite(f"{name}[1]", b))


def _finite_array(name: str, value: npt.ArrayLike) -> np.ndarray:
    try:
        arr = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be finite numbers, got {value!r}") from None
    if not np.all(np.isfinite(arr)):
        raise ValueError(f"{name} must be finite numbers, got {value!r}")
    return arr


def allocate_force_moment(
    X: npt.ArrayLike,
    N: npt.ArrayLike,
    *,
    pod_x: float | tuple[float, float] = POD_X,
    pod_y: float | tuple[float, float] = POD_Y,
    max_thrust: float = BOLLARD_THRUST,
    max_azimuth: float = ENV_MAX_AZIMUTH,
    priority: Literal["yaw", "surge"] = "yaw",
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Pod thrusts and azimuths that give surge force ``X`` and yaw moment ``N``.

    Parameters
    ----------
    X : array_like
        Desired surge force [N] (total of both pods).
    N : array_like
        Desired yaw moment [N m] (positive turns to starboard). Broadcast with ``X``.
    pod_x, pod_y : float or pair of float
        Pod positions [m] (port pod first); ``sum(pod_x)`` must be non-zero.
    max_thrust : float
        Per-pod thrust limit [N] (e.g. ``T_bollard (1 - u_r / u_0)`` at the present speed).
    max_azimuth : float
        Azimuth limit [rad], in (0, pi/2].
    priority : {"yaw", "surge"}
        Which request to keep when both cannot be met (module docstring).

    Returns
    -------
    tuple of numpy.ndarray
        ``(T1, T2, a1, a2)``: thrust [N] and azimuth [rad] of each pod (equal pairs), in the
        broadcast shape of ``X`` and ``N``.

    Raises
    ------
    ValueError
        For non-finite inputs, bad limits, pods whose ``x`` sum to zero or an unknown priority.
    """
    x1, x2 = _pair("pod_x", pod_x)
    y1, y2 = _pair("pod_y", pod_y)
    if x1 + x2 == 0:
        raise ValueError(f"pod_x must not sum to zero (no yaw moment from azimuth), got {pod_x!r}")
    tmax = positive("max_thrust", max_thrust)
    amax = positive("max_azimuth", max_azimuth)
    if amax > math.pi / 2 + 1e-12:
        raise ValueError(f"max_azimuth must be in (0, pi/2] rad (no astern thrust), got {amax!r}")
    if priority not in ("yaw", "surge"):
        raise ValueError(f"priority must be 'yaw' or 'surge', got {priority!r}")
    Xa, Na = np.broadcast_arrays(_finite_array("X", X), _finite_array("N", N))
    c = 0.5 * Xa
    s = (Na + (y1 + y2) * c) / (x1 + x2)
    sin_max = math.sin(amax)
    cot_max = math.cos(amax) / sin_max  # 0 at 90 deg
    if priority == "yaw":
        s_new = np.clip(s, -tmax * sin_max, tmax * sin_max)
        c_high = np.sqrt(np.maximum(tmax * tmax - s_new * s_new, 0.0))
        c_low = np.minimum(np.abs(s_new) * cot_max, c_high)
        c_new = np.clip(c, c_low, c_high)
    else:
        c_new = np.clip(c, 0.0, tmax)
        s_lim = np.sqrt(np.maximum(tmax * tmax - c_new * c_new, 0.0))
        if amax < math.pi / 2:
            s_lim = np.minimum(s_lim, c_new * math.tan(amax))
        s_new = np.clip(s, -s_lim, s_lim)
    thrust = np.minimum(np.hypot(c_new, s_new), tmax)
    azimuth = np.where(thrust > 0, np.arctan2(s_new, c_new), 0.0)
    azimuth = np.clip(azimuth, -amax, amax)
    return thrust, thrust.copy(), azimuth, azimuth.copy()


def pod_forces(
    T1: npt.ArrayLike,
    T2: npt.ArrayLike,
    a1: npt.ArrayLike,
    a2: npt.ArrayLike,
    *,
    pod_x: float | tuple[float, float] = POD_X,
    pod_y: float | tuple[float, float] = POD_Y,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Surge force, sway force and yaw moment ``(X, Y, N)`` of two pods (seed 001 eq. 20)."""
    x1, x2 = _pair("pod_x", pod_x)
    y1, y2 = _pair("pod_y", pod_y)
    t1, t2 = _finite_array("T1", T1), _finite_array("T2", T2)
    b1, b2 = _finite_array("a1", a1), _finite_array("a2", a2)
    X = t1 * np.cos(b1) + t2 * np.cos(b2)
    Y = t1 * np.sin(b1) + t2 * np.sin(b2)
    N = t1 * (-y1 * np.cos(b1) + x1 * np.sin(b1)) + t2 * (-y2 * np.cos(b2) + x2 * np.sin(b2))
    return X, Y, N


def azimuth_to_action(azimuth: float, max_azimuth: float = ENV_MAX_AZIMUTH) -> float:
    """Normalised azimuth action ``alpha / a_max`` (inverse of the envs' ``alpha = a_max a``)."""
    return finite("azimuth", azimuth) / positive("max_azimuth", max_azimuth)


def thrust_to_action(thrust: float, bollard_thrust: float = BOLLARD_THRUST) -> float:
    """Normalised thrust action ``2 T / T_b - 1`` (inverse of ``T = T_b / 2 (1 + a)``)."""
    return 2.0 * finite("thrust", thrust) / positive("bollard_thrust", bollard_thrust) - 1.0


def pod_env_actions(
    azimuth: npt.ArrayLike,
    thrust: npt.ArrayLike,
    env: EnvName = "path",
    *,
    max_azimuth: float = ENV_MAX_AZIMUTH,
    bollard_thrust: float = BOLLARD_THRUST,
    clip: bool = True,
) -> np.ndarray:
    """The normalised actions of a Gunnerus env that give common pod commands, one row per ship.

    ``azimuth`` [rad] and ``thrust`` [N] are scalars or arrays of shape ``(n,)``
    (broadcast together); the rows are those of :meth:`PodCommand.to_env_action` of each
    ship's command. Returns a ``float32`` array of shape ``(n, 1)`` or ``(n, 2)``.
    """
    if env not in _ENVS:
        raise ValueError(f"env must be one of {_ENVS}, got {env!r}")
    az = np.atleast_1d(_finite_array("azimuth", azimuth)) / positive("max_azimuth", max_azimuth)
    th = (
        2.0 * np.atleast_1d(_finite_array("thrust", thrust))
        / positive("bollard_thrust", bollard_thrust) - 1.0
    )  # fmt: skip
    az, th = np.broadcast_arrays(az, th)
    if env == "heading":
        out = az[:, None]
    elif env == "speed":
        out = th[:, None]
    else:
        out = np.stack([az, th], axis=1)
    if clip:
        out = np.clip(out, -1.0, 1.0)
    return out.astype(np.float32)


@dataclass(frozen=True)
class PodCommand:
    """A common command to both Gunnerus pods in physical units.

    Attributes
    ----------
    azimuth : float
        Azimuth of both pods [rad] (positive turns the ship to port).
    thrust : float
        Thrust of each pod [N].
    """

    azimuth: float
    thrust: float

    def __post_init__(self) -> None:
        object.__setattr__(self, "azimuth", finite("azimuth", self.azimuth))
        object.__setattr__(self, "thrust", finite("thrust", self.thrust))

    def model_input(self) -> np.ndarray:
        """The RVG model input ``[T1_c, T2_c, alpha1_c, alpha2_c]`` [N, N, rad, rad]."""
        return np.array([self.thrust, self.thrust, self.azimuth, self.azimuth])

    def to_env_action(
        self,
        env: EnvName = "path",
        *,
        max_azimuth: float = ENV_MAX_AZIMUTH,
        bollard_thrust: float = BOLLARD_THRUST,
        clip: bool = True,
    ) -> np.ndarray:
        """The normalised action of a Gunnerus env that gives this command.

        The inverse of the env's ``u = u0 + B a`` (module docstring):

        * ``"heading"``: ``[azimuth / a_max]`` (the thrust is fixed by the env at the service
          thrust; ``self.thrust`` is ignored);
        * ``"speed"``: ``[2 T / T_b - 1]`` (the azimuth is fixed at 0; ``self.azimuth`` is
          ignored);
        * ``"path"``, ``"target"``: ``[azimuth / a_max, 2 T / T_b - 1]``.

        Parameters
        ----------
        env : {"heading", "speed", "path", "target"}
            The env family.
        max_azimuth, bollard_thrust : float
            The env's scaling (35 deg, 121.7 kN by default).
        clip : bool
            Clip to [-1, 1] as the env does (default). Without clipping a value outside
            shows a command the env cannot give.

        Returns
        -------
        numpy.ndarray
            ``float32`` action of shape ``(1,)`` or ``(2,)``.
        """
        return pod_env_actions(
            self.azimuth, self.thrust, env, max_azimuth=max_azimuth,
            bollard_thrust=bollard_thrust, clip=clip,
        )[0]  # fmt: skip

    @classmethod
    def from_env_action(
        cls,
        action: npt.ArrayLike,
        env: EnvName = "path",
        *,
        max_azimuth: float = ENV_MAX_AZIMUTH,
        bollard_thrust: float = BOLLARD_THRUST,
        service_thrust: float = 25.0e3,
    ) -> PodCommand:
        """The command an env action gives (the env's own mapping, actions clipped to [-1, 1]).

        ``service_thrust`` [N] is the heading env's fixed thrust; the speed env's azimuth is 0.
        """
        a = np.clip(_finite_array("action", action), -1.0, 1.0).ravel()
        amax = positive("max_azimuth", max_azimuth)
        half = 0.5 * positive("bollard_thrust", bollard_thrust)
        sizes = {"heading": 1, "speed": 1, "path": 2, "target": 2}
        if env not in sizes:
            raise ValueError(f"env must be one of {_ENVS}, got {env!r}")
        if a.size != sizes[env]:
            raise ValueError(f"a {env!r} env action has {sizes[env]} values, got {action!r}")
        if env == "heading":
            return cls(amax * float(a[0]), finite("service_thrust", service_thrust))
        if env == "speed":
            return cls(0.0, half * (1.0 + float(a[0])))
        return cls(amax * float(a[0]), half * (1.0 + float(a[1])))
