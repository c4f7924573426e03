"""Per-camera background subtraction on the depth (Z) image alone (seed 003, section 3.1).

The seed's equations did not survive; what it keeps says: the segmentation uses the Z image
alone, the background is initialised over the first frames, invalid pixels have their own
rule during and after the initialisation, valid pixels are updated by a weighted average with
a small weight, and a point is foreground when it lies nearer than the background. The rules
implemented here, stated once:

- Initialisation (the first ``init_frames`` frames): the background is the mean of each
  pixel's valid samples. A pixel never valid during it (beyond range, a window, the sky) gets
  an infinitely far background, so whatever later appears there is foreground.
- After it, an invalid pixel leaves the weighted average unchanged (it carries no depth).
  But where a finite background has given no return for ``init_frames`` frames in a row,
  the background becomes infinitely far: no return is the farthest a pixel can be, and this
  is the revealed-surface rule below with no surface behind. Without it a pixel that looks
  at nothing (the sky, beyond range) keeps as background whoever walked through it while the
  background was learnt (the mean of its few valid samples), and a person later passing
  behind that phantom is never foreground: at Fig. 8's level camera, one person of three
  was lost for 2-3 s per pass that way.
- A valid pixel ``z`` first enters the weighted average ``B <- (1 - a) B + a z`` with
  ``a = 1 - exp(-dt / tau)`` (a time constant, so the behaviour does not depend on the frame
  rate); then, where ``z`` has lain farther than ``B`` by more than the margin for
  ``init_frames`` frames in a row (a surface that was occluded while the background was
  learnt is revealed), ``B <- z``. One farther sample is not enough: with depth noise
  comparable to the margin, single samples beyond it are common, and adopting each of them
  pushes ``B`` to the far tail of the noise, after which ordinary samples lie "nearer by
  more than the margin" and the whole static scene turns to foreground (measured on scene 2
  with 50 mm of added noise: 41% of the pixels instead of the 2.3% the margin alone
  allows). A pixel with an infinitely far background takes ``z`` once ``z`` has been seen
  there for ``init_frames`` frames in a row (an object placed beyond range and left there).
- Foreground: valid and nearer than the background by more than ``margin_m``.

Stationary objects fade into the background over a few time constants, as the seed says
(section 3, note on segmentation). The alternative is OpenCV's Gaussian mixture (MOG2, two
mixtures), which the seed switched to for noise beyond 50 mm (Fig. 10, Matlab's
``vision.ForegroundDetector`` with two Gaussians).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Protocol

import cv2
import numba
import numpy as np
from numpy.typing import NDArray

BoolImage = NDArray[np.bool_]
DepthImage = NDArray[np.float32]


class BackgroundSubtractor(Protocol):
    """A per-camera background model fed every depth frame in order."""

    def apply(self, depth: DepthImage, dt_s: float) -> BoolImage:
        """Foreground mask of this frame (all False while initialising), then learn from it."""
        ...


def _check_common(init_frames: int, time_constant_s: float) -> None:
    if init_frames < 1:
        raise ValueError(f"init_frames={init_frames} must be >= 1")
    if not time_constant_s > 0:
        raise ValueError(f"time_constant_s={time_constant_s} must be > 0")


class RunningAverageBackground:
    """The seed's running-average background on the Z image (rules in the module docstring)."""

    def __init__(self, init_frames: int, time_constant_s: float, margin_m: float) -> None:
        _check_common(init_frames, time_constant_s)
        if not margin_m > 0:
            raise ValueError(f"margin_m={margin_m} must be > 0")
        self.init_frames = init_frames
        self.time_constant_s = time_constant_s
        self.margin_m = margin_m
        self.frames = 0
        self._sum: NDArray[np.float64] | None = None
        self._count: NDArray[np.int32] | None = None
        # After the initialisation: the background and, per pixel, how many frames in a row
        # it has been valid (infinitely far background) or farther than the background by
        # more than the margin (finite background).
        self._state: tuple[DepthImage, NDArray[np.int32]] | None = None

    @property
    def background(self) -> DepthImage | None:
        """The background depth (m; +inf: never seen), None while initialising."""
        return None if self._state is None else self._state[0]

    def apply(self, depth: DepthImage, dt_s: float) -> BoolImage:
        z = np.asarray(depth, dtype=np.float32)
        valid = np.isfinite(z)
        if self._state is None:
            self._accumulate(z, valid)
            return np.zeros(z.shape, dtype=bool)
        B, streak = self._state
        if B.shape != z.shape:
            raise ValueError(f"depth image is {z.shape}, the background model is {B.shape}")
        alpha = np.float32(1.0 - math.exp(-max(dt_s, 0.0) / self.time_constant_s))
        foreground = np.empty(z.shape, dtype=np.bool_)
        _running_average_kernel(
            np.ascontiguousarray(z).reshape(-1),
            B.reshape(-1),
            streak.reshape(-1),
            alpha,
            np.float32(self.margin_m),
            self.init_frames,
            foreground.reshape(-1),
        )
        return foreground

    def _accumulate(self, z: DepthImage, valid: BoolImage) -> None:
        if self._sum is None or self._count is None:
            self._sum = np.zeros(z.shape, dtype=np.float64)
            self._count = np.zeros(z.shape, dtype=np.int32)
        elif self._sum.shape != z.shape:
            raise ValueError(f"depth image is {z.shape}, the background model is {self._sum.shape}")
        self._sum += np.where(valid, z, 0.0)
        self._count += valid
        self.frames += 1
        if self.frames >= self.init_frames:
            with np.errstate(invalid="ignore", divide="ignore"):
                mean = self._sum / self._count
            background = np.where(self._count > 0, mean, np.inf).astype(np.float32)
            self._state = (background, np.zeros(z.shape, dtype=np.int32))
            self._sum = None
            self._count = None


def _running_average_step(
    z: DepthImage,
    B: DepthImage,
    streak: NDArray[np.int32],
    alpha: np.float32,
    margin: np.float32,
    init_frames: int,
    foreground: BoolImage,
) -> None:
    """One frame of the running average on flat images, in place (rules: module docstring)."""
    for i in range(z.shape[0]):
        zi = z[i]
        b = B[i]
        # streak > 0: frames in a row farther than B (or valid, if B is infinitely far);
        # streak < 0: frames in a row without a return while B is finite.
        if not math.isfinite(zi):  # invalid: no depth, the average is kept
            foreground[i] = False
            if math.isinf(b):
                streak[i] = 0
                continue
            s = min(streak[i], 0) - 1
            if -s >= init_frames:  # no return for long: nothing there, B infinitely far
                B[i] = math.inf
                s = 0
            streak[i] = s
            continue
        if math.isinf(b):  # never-seen background: foreground, adopted after a streak
            foreground[i] = True
            s = max(streak[i], 0) + 1
            if s >= init_frames:
                B[i] = zi
                s = 0
            streak[i] = s
            continue
        foreground[i] = b - zi > margin
        b = b + alpha * (zi - b)  # step 1: weighted average
        if zi - b > margin:  # step 2: a farther surface, revealed once seen long enough
            s = max(streak[i], 0) + 1
            if s >= init_frames:
                b = zi
                s = 0
            streak[i] = s
        else:
            streak[i] = 0
        B[i] = b


#: Compiled on first use and cached on disk: one pass instead of a dozen full-image ufuncs.
_running_average_kernel: Callable[
    [DepthImage, DepthImage, NDArray[np.int32], np.float32, np.float32, int, BoolImage], None
] = numba.njit(cache=True)(_running_average_step)


#: The value MOG2 sees at a pixel never valid (m): farther than any depth camera's range, as
#: the running average's infinitely far background; within [0, 255], the range OpenCV
#: documents for floating-point frames.
NO_RETURN_M = 100.0


class Mog2Background:
    """OpenCV's MOG2 with two mixtures on the depth image in metres (seed 003, Fig. 10).

    An invalid pixel carries no information (as in the running average): MOG2 sees the
    pixel's last valid depth again, or :data:`NO_RETURN_M` (farther than any depth camera's
    range) if it has never been valid; it is never foreground. Nor is what lies farther than
    MOG2's background image (a revealed surface, not an object). Two other encodings failed
    on scene 2: 0 m made a pixel that never returns (the void above the floor's far edge) a
    background nearer than any person, so people seen against it were never foreground; a
    fixed far value made every pixel with occasional dropouts spend one of its two modes on
    that value, so that the first person to pass replaced the true background's mode, which
    was foreground from then on. MOG2's
    variances are set in metres squared (its defaults are for 8-bit intensities). The
    learning rate follows the same time constant as the running average; the first
    ``init_frames`` frames learn with rate ``1/n`` (a plain mean) and report no foreground.
    """

    def __init__(
        self,
        init_frames: int,
        time_constant_s: float,
        var_threshold: float,
        var_init_m2: float,
        var_min_m2: float,
        var_max_m2: float,
    ) -> None:
        _check_common(init_frames, time_constant_s)
        if not 0 < var_min_m2 <= var_init_m2 <= var_max_m2:
            raise ValueError(
                f"MOG2 variances must satisfy 0 < min ({var_min_m2}) <= init ({var_init_m2}) "
                f"<= max ({var_max_m2})"
            )
        if not var_threshold > 0:
            raise ValueError(f"var_threshold={var_threshold} must be > 0")
        self.init_frames = init_frames
        self.time_constant_s = time_constant_s
        self.frames = 0
        mog = cv2.createBackgroundSubtractorMOG2(
            history=max(init_frames, 1), varThreshold=var_threshold, detectShadows=False
        )
        mog.setNMixtures(2)
        mog.setVarInit(var_init_m2)
        mog.setVarMin(var_min_m2)
        mog.setVarMax(var_max_m2)
        self._mog = mog
        #: per pixel, the depth MOG2 last saw (an invalid pixel repeats it)
        self._last: DepthImage | None = None

    def apply(self, depth: DepthImage, dt_s: float) -> BoolImage:
        z = np.asarray(depth, dtype=np.float32)
        valid = np.isfinite(z)
        if self._last is None or self._last.shape != z.shape:
            self._last = np.full(z.shape, NO_RETURN_M, dtype=np.float32)
        image = np.where(valid, z, self._last).astype(np.float32)
        self._last = image
        self.frames += 1
        if self.frames <= self.init_frames:
            self._mog.apply(image, learningRate=1.0 / self.frames)
            return np.zeros(z.shape, dtype=bool)
        rate = 1.0 - math.exp(-max(dt_s, 0.0) / self.time_constant_s)
        mask = self._mog.apply(image, learningRate=rate)
        # Foreground is what lies nearer than the background (seed 003, 3.1): MOG2 flags any
        # change, also a surface revealed behind someone who left (a "ghost" farther away).
        background = self._mog.getBackgroundImage()
        foreground: BoolImage = (mask > 0) & valid & (z < background)
        return foreground
