"""Search settings: one weights object (:class:`SearchWeights`) and one window/index object
(:class:`WindowConfig`). Both are frozen, validated on construction and hashable into the index
fingerprint, so a saved index knows which settings built it."""

from __future__ import annotations

import hashlib
import json
import math
from dataclasses import asdict, dataclass, fields
from typing import Any, TypeVar

import numpy as np
from numpy.typing import NDArray

from reactmocap.errors import ConfigError

__all__ = ["SearchWeights", "WindowConfig", "settings_hash"]


def _check_nonneg(obj: object, names: tuple[str, ...]) -> None:
    for n in names:
        v = getattr(obj, n)
        if not isinstance(v, (int, float)) or isinstance(v, bool) or not math.isfinite(v) or v < 0:
            raise ConfigError(f"{type(obj).__name__}.{n} must be a finite number >= 0, got {v!r}")


_T = TypeVar("_T")


@dataclass(frozen=True)
class SearchWeights:
    """Every weight of the window distance ``D`` (the paper's intent as defaults).

    ``D(Wa, Wb) = sum_i w_i sum_b (w_pb |p_b(a_i) - p_b(b_i)| + w_thb d_theta(a_i, b_i))``

    * ``w_i``: quadratic window weight ``floor + (1 - floor) ((L - i) / L)^2``, highest at the
      first frame, normalised to sum to 1 (so ``D`` is a per-frame average and comparable across
      window lengths).
    * ``w_pb`` (per metre) and ``w_thb`` (per unit of ``d_theta``, ~radian): ``trunk_*`` for the
      trunk parts, ``limb_*`` for the limbs. The ground-support body chosen for the *query* gets
      ``max(base, support_*)`` for the whole window.
    * ``support_height``: hands and pelvis count as ground support when they are within this many
      metres of the lowest mapped body part at the query's first frame (a fallen character);
      the feet always count.
    * ``stance_mismatch``: added to ``D`` for each foot whose ground contact at the window's first
      frame differs between query and library window (counted in the support position term), so
      a continuation standing on the other foot, or flying where the body stands, pays for the
      blend that would drag the feet there. A foot is in contact when it is at most
      ``contact_height`` m above the ground and moves horizontally at most ``contact_speed`` m/s
      (from the first two window frames). The KD embedding holds each foot's contact beside
      its PCA dimensions and the index keeps a window start wherever a contact changes, so the
      indexed search finds the optimum as often as without the term. 0.2 by default (the real
      recipients' blend mode: 13 -> 15 of 40 clean); 0 turns it off (``docs/benchmarks.md``,
      "Reactions that react", the stance-mismatch cost).
    * ``feature_set``: key into :data:`reactmocap.search.features.FEATURE_SETS`.
    """

    feature_set: str = "paper"
    trunk_position: float = 1.0
    trunk_orientation: float = 0.5
    limb_position: float = 0.25
    limb_orientation: float = 0.1
    support_position: float = 2.0
    support_orientation: float = 0.25
    support_height: float = 0.25
    window_floor: float = 0.0
    stance_mismatch: float = 0.2
    contact_height: float = 0.15
    contact_speed: float = 0.5

    def __post_init__(self) -> None:
        from reactmocap.search.features import get_feature_set

        if not isinstance(self.feature_set, str):
            raise ConfigError(
                f"SearchWeights.feature_set must be a string, got {self.feature_set!r}"
            )
        get_feature_set(self.feature_set)  # UnknownKeyError listing the valid keys
        _check_nonneg(
            self,
            (
                "trunk_position", "trunk_orientation", "limb_position", "limb_orientation",
                "support_position", "support_orientation", "support_height", "window_floor",
                "stance_mismatch", "contact_height", "contact_speed",
            ),
        )  # fmt: skip
        if self.window_floor > 1:
            raise ConfigError(
                f"SearchWeights.window_floor must be in [0, 1], got {self.window_floor}"
            )
        if (
            self.trunk_position
            + self.trunk_orientation
            + self.limb_position
            + self.limb_orientation
            == 0
        ):
            raise ConfigError("SearchWeights: all body weights are zero")

    def window_weights(self, length: int) -> NDArray[np.float64]:
        """``(L,)`` quadratic window weights, highest at frame 0, summing to 1."""
        i = np.arange(length, dtype=np.float64)
        w = self.window_floor + (1.0 - self.window_floor) * ((length - i) / length) ** 2
        return w / w.sum()

    def to_dict(self) -> dict[str, Any]:
        return asdict(self)

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> SearchWeights:
        return _from_dict(cls, data)


@dataclass(frozen=True)
class WindowConfig:
    """Window and index settings.

    * ``fps``: the index rate. Library clips are resampled to it at build time, queries at query
      time.
    * ``duration``: seconds covered by a window; ``L = round(duration * fps) + 1`` frames.
    * ``unique_tolerance``: unique-frame tolerance, in units of ``D`` of a one-frame window (base
      weights, each frame in its own root frame): a frame is dropped as a window start when the
      pose path length since the previous kept frame is below it. Independent of ``fps``.
    * ``max_gap``: seconds; a start is kept at least this often whatever the tolerance, which
      bounds the refinement interval.
    * ``embed_frames``: window frames that enter the KD embedding (exact ``D`` uses all ``L``).
    * ``pca_dims``: PCA dimensions of the KD embedding (0: no PCA).
    """

    fps: float = 30.0
    duration: float = 0.3
    unique_tolerance: float = 0.1
    max_gap: float = 0.2
    embed_frames: int = 6
    pca_dims: int = 32

    def __post_init__(self) -> None:
        _check_nonneg(self, ("fps", "duration", "unique_tolerance", "max_gap"))
        if self.fps <= 0:
            raise ConfigError(f"WindowConfig.fps must be > 0, got {self.fps}")
        for n in ("embed_frames", "pca_dims"):
            v = getattr(self, n)
            if not isinstance(v, int) or isinstance(v, bool) or v < 0:
                raise ConfigError(f"WindowConfig.{n} must be an integer >= 0, got {v!r}")
        if self.embed_frames < 1:
            raise ConfigError("WindowConfig.embed_frames must be >= 1")
        if self.length > 10_000:
            raise ConfigError(f"WindowConfig: window of {self.length} frames is unreasonably long")

    @property
    def length(self) -> int:
        """Frames per window, ``L``."""
        return round(self.duration * self.fps) + 1

    @property
    def max_gap_frames(self) -> int:
        return max(1, round(self.max_gap * self.fps))

    def embed_offsets(self) -> NDArray[np.int64]:
        """Frame offsets inside the window that enter the KD embedding (always includes 0)."""
        e = min(self.embed_frames, self.length)
        return np.unique(np.round(np.linspace(0, self.length - 1, e)).astype(np.int64))

    def to_dict(self) -> dict[str, Any]:
        return asdict(self)

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> WindowConfig:
        return _from_dict(cls, data)


def _from_dict(cls: type[_T], data: dict[str, Any]) -> _T:
    """Build a config dataclass from a dict, naming any unknown field."""
    known = {f.name for f in fields(cls)}  # type: ignore[arg-type]
    unknown = set(data) - known
    if unknown:
        raise ConfigError(
            f"{cls.__name__}: unknown fields {sorted(unknown)}; known {sorted(known)}"
        )
    return cls(**data)


_STANCE_FIELDS = ("stance_mismatch", "contact_height", "contact_speed")


def settings_hash(weights: SearchWeights, window: WindowConfig, mirror: bool) -> str:
    w = weights.to_dict()
    if weights.stance_mismatch == 0:
        # the stance term off changes nothing: indexes saved before it existed stay valid
        for k in _STANCE_FIELDS:
            del w[k]
    blob = json.dumps(
        {"weights": w, "window": window.to_dict(), "mirror": bool(mirror)},
        sort_keys=True,
    )
    return hashlib.sha256(blob.encode()).hexdigest()
