"""The bicycle's parameters (Hodgins et al. 1995, "Bicycling"; Meijaard et al. 2007): wheels,
frame parts, drivetrain and rider fit; the benchmark bicycle (:data:`BENCHMARK`, Meijaard et al.
2007, Table 1) and the rider's (:data:`RIDER_BICYCLE`); and the benchmark's linearised model
(:func:`benchmark_matrices`), a cross-check for the simulation
(:mod:`reactmocap.athletics.stability`). Frames and signs as :mod:`reactmocap.athletics.bicycle`,
which builds the MuJoCo model from these and re-exports them."""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np
from numpy.typing import NDArray

from reactmocap.errors import ConfigError

__all__ = [
    "BENCHMARK",
    "BENCHMARK_CAPSIZE_SPEED",
    "BENCHMARK_WEAVE_SPEED",
    "FALLEN_ROLL",
    "RIDER_BICYCLE",
    "BicycleParams",
    "Drivetrain",
    "Fit",
    "Part",
    "WHEEL_SHAPES",
    "Wheel",
    "benchmark_matrices",
    "linear_eigenvalues",
]

F64 = NDArray[np.float64]
#: Meijaard et al. 2007, section 4: the benchmark's weave and capsize speeds (m/s)
BENCHMARK_WEAVE_SPEED = 4.292382208689
BENCHMARK_CAPSIZE_SPEED = 6.024262423973
#: wheel collision shapes: the flat ellipsoid is the knife-edge wheel; the others for comparison
WHEEL_SHAPES = ("ellipsoid", "cylinder", "sphere")
#: a bicycle below this roll (rad) has fallen: its handlebar or pedal is on the ground
FALLEN_ROLL = math.radians(60.0)


@dataclass(frozen=True)
class Wheel:
    """A wheel: ``radius`` (m), ``mass`` (kg), diametral ``ixx`` and polar ``iyy`` (kg m^2)."""

    radius: float
    mass: float
    ixx: float
    iyy: float


@dataclass(frozen=True)
class Part:
    """A rigid part: ``mass`` (kg), centre of mass ``(x, z)`` in the bicycle frame (m, from the
    rear contact point), inertia ``(ixx, iyy, izz, ixz)`` about it in the bicycle frame."""

    mass: float
    com: tuple[float, float]
    inertia: tuple[float, float, float, float]


@dataclass(frozen=True)
class Drivetrain:
    """Crank and fixed gear. ``gear``: rear-wheel turns per crank turn; ``crank_length`` (m);
    ``bottom_bracket`` ``(x, z)`` (m); ``pedal_offset``: lateral distance of each pedal point
    from the centre plane (m); ``crank`` the crank set's mass and polar inertia; ``chain``: the
    gear equality's spring-damper (time constant s, damping ratio)."""

    gear: float = 2.8
    crank_length: float = 0.17
    bottom_bracket: tuple[float, float] = (0.40, 0.28)
    pedal_offset: float = 0.09
    crank_mass: float = 1.0
    crank_inertia: float = 0.01
    chain: tuple[float, float] = (0.01, 1.0)


@dataclass(frozen=True)
class Fit:
    """Where a rider sits and holds: the saddle point ``(x, z)`` and the grips ``(x, z)`` (m,
    with the steer at zero), each grip ``grip_offset`` m from the centre plane."""

    seat: tuple[float, float] = (0.16, 1.03)
    grips: tuple[float, float] = (0.70, 1.07)
    grip_offset: float = 0.25


@dataclass(frozen=True)
class BicycleParams:
    """A bicycle's geometry and mass (the benchmark's parameter names in the comments).

    Attributes:
        wheelbase: ``w`` (m). trail: ``c`` (m). steer_tilt: ``lambda`` (rad, from vertical,
            the top of the steer axis behind its foot).
        rear, front: the wheels ``R`` and ``F``. frame: rear body ``B``. fork: front frame and
            handlebar ``H``.
        rolling_resistance: total resistive force per unit speed (N s/m), half at each wheel.
        tyre: the wheel ellipsoid's half width (m); wheel_contact: its contact time constant
            (s) and damping ratio; noslip: MuJoCo noslip iterations; wheel_shape: the wheel's
            collision shape, ``"ellipsoid"`` (the knife edge) or, to show why not,
            ``"cylinder"`` or ``"sphere"``.
        drivetrain, fit: for a rider (``None``: the bare benchmark).
    """

    wheelbase: float
    trail: float
    steer_tilt: float
    rear: Wheel
    front: Wheel
    frame: Part
    fork: Part
    rolling_resistance: float = 0.0
    tyre: float = 0.002
    wheel_contact: tuple[float, float] = (0.004, 1.0)
    noslip: int = 10
    wheel_shape: str = "ellipsoid"
    drivetrain: Drivetrain | None = None
    fit: Fit | None = None

    def __post_init__(self) -> None:
        pos = {"wheelbase": self.wheelbase, "rear radius": self.rear.radius,
               "front radius": self.front.radius, "rear mass": self.rear.mass,
               "front mass": self.front.mass, "frame mass": self.frame.mass,
               "fork mass": self.fork.mass, "tyre": self.tyre,
               "wheel contact time constant": self.wheel_contact[0]}  # fmt: skip
        for name, v in pos.items():
            if not (math.isfinite(v) and v > 0):
                raise ConfigError(f"bicycle {name} must be > 0, got {v!r}")
        if not (math.isfinite(self.trail) and math.isfinite(self.steer_tilt)
                and abs(self.steer_tilt) < math.pi / 2):  # fmt: skip
            raise ConfigError("bicycle trail must be finite and steer_tilt within +-90 degrees")
        if not (math.isfinite(self.rolling_resistance) and self.rolling_resistance >= 0):
            raise ConfigError(f"rolling_resistance must be >= 0, got {self.rolling_resistance!r}")
        if self.tyre >= 0.2 * min(self.rear.radius, self.front.radius):
            raise ConfigError("the tyre half width must be well under the wheel radius")
        for name, w in (("rear", self.rear), ("front", self.front)):
            if not (w.ixx > 0 and w.iyy > 0 and w.iyy <= 2 * w.ixx + 1e-12):
                raise ConfigError(f"{name} wheel inertia must be > 0 with iyy <= 2 ixx")
        dt = self.drivetrain
        if dt is not None and not (dt.gear > 0 and dt.crank_length > 0 and dt.crank_mass > 0
                                   and dt.crank_inertia > 0 and dt.chain[0] > 0):  # fmt: skip
            raise ConfigError("drivetrain gear, crank length, mass, inertia and chain must be > 0")
        if self.wheel_shape not in WHEEL_SHAPES:
            raise ConfigError(
                f"wheel_shape must be one of {list(WHEEL_SHAPES)}, got {self.wheel_shape!r}"
            )
        if self.noslip < 0:
            raise ConfigError(f"noslip iterations must be >= 0, got {self.noslip!r}")

    @property
    def steer_axis(self) -> F64:
        """Unit vector up the steer axis (bicycle frame)."""
        return np.array([-math.sin(self.steer_tilt), 0.0, math.cos(self.steer_tilt)])

    @property
    def steer_foot(self) -> F64:
        """Where the steer axis meets the ground (bicycle frame)."""
        return np.array([self.wheelbase + self.trail, 0.0, 0.0])

    @property
    def mass(self) -> float:
        dt = self.drivetrain
        return (self.rear.mass + self.front.mass + self.frame.mass + self.fork.mass
                + (dt.crank_mass if dt is not None else 0.0))  # fmt: skip

    def with_gear(self, gear: float) -> BicycleParams:
        if self.drivetrain is None:
            raise ConfigError("this bicycle has no drivetrain")
        return replace(self, drivetrain=replace(self.drivetrain, gear=float(gear)))


#: Meijaard, Papadopoulos, Ruina & Schwab (2007), "Linearized dynamics equations for the balance
#: and steer of a bicycle: a benchmark and review", Proc. R. Soc. A 463, Table 1 (their z down
#: and I_xz sign flipped into our Z-up frame):
#:
#: ======================  ==========================================  =====================
#: wheelbase w             1.02 m                                       trail c 0.08 m
#: steer axis tilt lambda  pi/10 rad                                    g 9.81 m/s^2
#: rear wheel R            r 0.3 m, m 2 kg, (Ixx, Iyy) (0.0603, 0.12)  kg m^2
#: rear body B             (x, z) (0.3, 0.9) m, m 85 kg                 I (9.2, 11, 2.8; Ixz -2.4)
#: front frame H           (x, z) (0.9, 0.7) m, m 4 kg                  I (0.05892, 0.06, 0.00708;
#:                                                                      Ixz 0.00756)
#: front wheel F           r 0.35 m, m 3 kg, (Ixx, Iyy) (0.1405, 0.28)  kg m^2
#: ======================  ==========================================  =====================
BENCHMARK = BicycleParams(
    wheelbase=1.02,
    trail=0.08,
    steer_tilt=math.pi / 10,
    rear=Wheel(0.3, 2.0, 0.0603, 0.12),
    front=Wheel(0.35, 3.0, 0.1405, 0.28),
    frame=Part(85.0, (0.3, 0.9), (9.2, 11.0, 2.8, -2.4)),
    fork=Part(4.0, (0.9, 0.7), (0.05892, 0.06, 0.00708, 0.00756)),
)

#: the rider's bicycle: the benchmark's geometry and wheels (validated), a real frame's mass
#: (8 kg frame and saddle, 2 kg fork, stem and bar; the benchmark's 85 kg rear body includes a
#: rider), a fixed-gear drivetrain and a saddle and grips fitted later to the rider
#: (:func:`reactmocap.athletics.rider.fit_bicycle`). Rolling resistance 3 N s/m lumps tyre
#: losses and air drag: 15 N (75 W) at 5 m/s, 30 N (300 W) at 10 m/s.
RIDER_BICYCLE = replace(
    BENCHMARK,
    frame=Part(8.0, (0.42, 0.62), (0.35, 0.6, 0.3, 0.05)),
    fork=Part(2.0, (0.85, 0.75), (0.08, 0.07, 0.03, 0.02)),
    rolling_resistance=3.0,
    drivetrain=Drivetrain(),
    fit=Fit(),
)


# ------------------------------------------------------------------------- linear benchmark
def benchmark_matrices(p: BicycleParams = BENCHMARK, g: float = 9.81) -> tuple[F64, F64, F64, F64]:
    """``M, C1, K0, K2`` ``(2, 2)`` of the linearised Whipple bicycle,
    ``M q'' + v C1 q' + (g K0 + v^2 K2) q = f`` with ``q = (roll, steer)`` in the benchmark's
    signs (Meijaard et al. 2007, Appendix A). A cross-check only: our figures come from
    simulating the MuJoCo model."""
    w, c, lam = p.wheelbase, p.trail, p.steer_tilt
    rr, rf = p.rear.radius, p.front.radius
    mr, mf, mb, mh = p.rear.mass, p.front.mass, p.frame.mass, p.fork.mass
    xb, zb = p.frame.com[0], -p.frame.com[1]  # back to the benchmark's z down
    xh, zh = p.fork.com[0], -p.fork.com[1]
    ibxx, _, ibzz, ibxz = p.frame.inertia
    ihxx, _, ihzz, ihxz = p.fork.inertia
    ibxz, ihxz = -ibxz, -ihxz
    irxx, iryy, ifxx, ifyy = p.rear.ixx, p.rear.iyy, p.front.ixx, p.front.iyy
    mt = mr + mb + mh + mf
    xt = (xb * mb + xh * mh + w * mf) / mt
    zt = (-rr * mr + zb * mb + zh * mh - rf * mf) / mt
    itxx = irxx + ibxx + ihxx + ifxx + mr * rr**2 + mb * zb**2 + mh * zh**2 + mf * rf**2
    itxz = ibxz + ihxz - mb * xb * zb - mh * xh * zh + mf * w * rf
    itzz = irxx + ibzz + ihzz + ifxx + mb * xb**2 + mh * xh**2 + mf * w**2
    ma = mh + mf
    xa, za = (xh * mh + w * mf) / ma, (zh * mh - rf * mf) / ma
    iaxx = ihxx + ifxx + mh * (zh - za) ** 2 + mf * (rf + za) ** 2
    iaxz = ihxz - mh * (xh - xa) * (zh - za) + mf * (w - xa) * (rf + za)
    iazz = ihzz + ifxx + mh * (xh - xa) ** 2 + mf * (w - xa) ** 2
    s, co = math.sin(lam), math.cos(lam)
    ua = (xa - w - c) * co - za * s
    iall = ma * ua**2 + iaxx * s * s + 2 * iaxz * s * co + iazz * co * co
    ialx = -ma * ua * za + iaxx * s + iaxz * co
    ialz = ma * ua * xa + iaxz * s + iazz * co
    mu = c / w * co
    sr, sf = iryy / rr, ifyy / rf
    st = sr + sf
    sa = ma * ua + mu * mt * xt
    m = np.array(
        [[itxx, ialx + mu * itxz], [ialx + mu * itxz, iall + 2 * mu * ialz + mu**2 * itzz]]
    )
    k0 = np.array([[mt * zt, -sa], [-sa, -sa * s]])
    k2 = np.array([[0.0, (st - mt * zt) / w * co], [0.0, (sa + sf * s) / w * co]])
    c1 = np.array([[0.0, mu * st + sf * co + itxz / w * co - mu * mt * zt],
                   [-(mu * st + sf * co), ialz / w * co + mu * (sa + itzz / w * co)]])  # fmt: skip
    del g
    return m, c1, k0, k2


def linear_eigenvalues(speed: float, p: BicycleParams = BENCHMARK, g: float = 9.81) -> NDArray:
    """``(4,)`` complex eigenvalues (1/s) of the linearised benchmark model at ``speed``."""
    m, c1, k0, k2 = benchmark_matrices(p)
    a = np.zeros((4, 4))
    a[:2, 2:] = np.eye(2)
    mi = np.linalg.inv(m)
    a[2:, :2] = -mi @ (g * k0 + speed**2 * k2)
    a[2:, 2:] = -mi @ (speed * c1)
    return np.sort_complex(np.linalg.eigvals(a))
