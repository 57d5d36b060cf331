"""Hologram and Image: complex fields with their coordinates attached.

Sample positions: ``data[..., iy, ix]`` is the field at ``(x[ix], y[iy])`` in
metres on the aperture plane z = 0 (element centres). An array of n elements at
pitch s covers the full width ``A = n*s`` (each element stands for one pitch),
so the paper's 16 x 16 array at 2.5 cm spans A = B = 40 cm.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from functools import cached_property
from typing import Any

import numpy as np

from .._validate import (
    as_axis,
    as_finite_complex,
    as_polarization,
    check_frequency,
    uniform_step,
)
from .band import Band
from .pose import IDENTITY, Pose
from .tx_offset import as_tx_offset

__all__ = ["C0", "Hologram", "Image"]

C0 = 299_792_458.0
"""Speed of light in vacuum, m/s."""


@dataclass(frozen=True, eq=False)
class Hologram(Band):
    """A complex field sampled on the aperture plane, at one or several frequencies.

    Parameters
    ----------
    data : array_like, complex, shape (..., ny, nx) or (..., nf, ny, nx)
        Field (the I + iQ of each element). With several frequencies, the
        frequency axis is third from last. Leading axes are frames (views,
        time) processed together.
    x : array_like, shape (nx,)
        Element x coordinates, metres, strictly increasing.
    y : array_like, shape (ny,), optional
        Element y coordinates, metres, strictly increasing. None (default): a line
        scan (a B-scan) along x, ``data`` (..., nx) or (..., nf, nx), kept as one row
        at y = 0; it images into an x-z section (the exact 2-D migration: targets
        that do not vary along y, bars and pipes across the line).
    frequency : float or array_like of shape (nf,)
        Frequency in Hz (> 0), or nf strictly increasing frequencies (a wideband
        hologram; ``data.shape[-3] == nf``).
    source : PlaneWave, PointSource or GaussianBeam, optional
        The illumination that produced the hologram (needed by multi-view
        synthesis, glare suppression and the coherent sum of frequencies).
    monostatic : bool
        True for a scanned transceiver: the sample at (x, y) is the field received
        by a transceiver at (x, y), so the wave travels there and back (round-trip
        wavenumber 2k); it has no separate ``source``. False (default): a
        receiver array lit by a separate source.
    pose : Pose, optional
        Where the aperture stands in the world (the medium's frame): its centre
        and tilt. ``x`` and ``y`` stay the element coordinates in the aperture's
        own plane; :attr:`points` gives their world positions. Default: the
        identity (the aperture on the plane z = 0, facing down).
    polarization : (float, float, float), optional
        Unit vector, in the scene's (world) axes, of the electric-field component
        the receivers record (normalised here): ``(0, 1, 0)`` for elements that
        record E_y. With it, and a source that has a polarisation (a
        :class:`~holoradar.Dipole`, or a plane wave, horn or beam given one),
        simulation, glare suppression, permittivity estimates and autofocus use
        the vector model (TE and TM waves, the dipole's near field). Default
        ``None``: the scalar model, in which the field is the tangential
        electric field of TE waves only.
    tx_offset : (float, float, float), optional
        A transmitter that moves with the receiver, metres: the sample at (x, y) is
        the field received at (x, y) of a transmitter at ``(x + dx, y + dy, dz)``
        (``dz`` towards the scene along the aperture's normal; two numbers: ``dz =
        0``). The echo of a point at ``r`` is then ``g(r_rx, r) g(r_tx, r)`` instead
        of a transceiver's ``g(r_rx, r)^2``; migration and the linear operator use it
        exactly. The hologram is then a scanned pair (``monostatic`` is True, no
        separate ``source``). ``None`` or ``(0, 0, 0)``: no offset (a transceiver
        when ``monostatic=True``). Longer than the aperture's diagonal is refused (a
        length in millimetres given as metres, most likely).

    Examples
    --------
    >>> import numpy as np
    >>> x = (np.arange(16) - 7.5) * 0.025
    >>> h = Hologram(np.zeros((16, 16), complex), x, x, 9.9e9)
    >>> round(h.aperture_size[0], 3), round(h.wavelength, 5)
    (0.4, 0.03028)
    >>> w = Hologram(np.zeros((3, 16, 16)), x, x, [9e9, 10e9, 11e9], monostatic=True)
    >>> w.nf, w.is_wideband
    (3, True)
    """

    data: np.ndarray
    x: np.ndarray
    y: np.ndarray
    frequency: float | np.ndarray
    source: Any = None
    monostatic: bool = False
    pose: Pose = IDENTITY
    polarization: np.ndarray | None = None
    tx_offset: tuple[float, float, float] | None = None

    def __init__(self, data: Any, x: Any, y: Any = None, frequency: Any = None, *,
                 source: Any = None, monostatic: bool = False,
                 pose: Pose | None = None, polarization: Any = None,
                 tx_offset: Any = None) -> None:
        if frequency is None:
            raise ValueError("frequency is needed: a number in Hz, or the band's "
                             "frequencies (Hologram(data, x, y, frequency) or, for a line "
                             "scan, Hologram(data, x, frequency=f))")
        if y is None:
            # A line scan (a B-scan): samples along x only, (..., [nf,] nx); kept as one
            # row at y = 0 (data (..., [nf,] 1, nx)).
            arr = as_finite_complex(data, "data", min_ndim=1)
            arr, y = arr[..., None, :], np.zeros(1)
        else:
            arr = as_finite_complex(data, "data", min_ndim=2)
        # A reversed axis, or one rounded to a text export's digits: made increasing
        # and uniform, said once (data/grid_axes.py).
        x, arr = _regular(x, arr, "x", -1)
        y, arr = _regular(y, arr, "y", -2)
        xa = as_axis(x, "x", length=arr.shape[-1])
        ya = as_axis(y, "y", length=arr.shape[-2])
        f = frequency_axis(frequency, arr.shape)
        if source is not None and not (hasattr(source, "field") and hasattr(source, "reflected")):
            raise ValueError("source must be a PlaneWave, PointSource, GaussianBeam or None, got "
                             f"{type(source).__name__}")
        if not isinstance(monostatic, bool | np.bool_):
            raise ValueError(f"monostatic must be True or False, got {monostatic!r}")
        offset = as_tx_offset(tx_offset, xa, ya)
        if offset is not None and source is not None:
            raise ValueError("a hologram with tx_offset has its transmitter beside each "
                             "receiver (it moves with it): it has no separate source; pass "
                             "source=None")
        monostatic = bool(monostatic) or offset is not None
        if monostatic and source is not None:
            raise ValueError("a monostatic hologram (scanned transceiver) has no separate "
                             "source: the transceiver at each sample lights the scene itself; "
                             "pass source=None")
        if pose is not None and not isinstance(pose, Pose):
            raise ValueError(f"pose must be a holoradar.Pose or None, got {type(pose).__name__}")
        pol = as_polarization(polarization, "polarization")
        if pol is not None:
            normal = (IDENTITY if pose is None else pose).normal
            if abs(float(pol @ normal)) > 1 - 1e-9:
                raise ValueError("polarization lies along the line of sight of every receiver "
                                 f"(the aperture's normal {np.round(normal, 6).tolist()}): the "
                                 "waves reaching the array have almost no field along it, so "
                                 "the receivers would record nothing; give the direction of "
                                 "the recorded component across the array, e.g. (0, 1, 0)")
        arr = arr.copy()  # the hologram owns its data: the caller's array is never shared
        arr.setflags(write=False)
        xa.setflags(write=False)
        ya.setflags(write=False)
        object.__setattr__(self, "data", arr)
        object.__setattr__(self, "x", xa)
        object.__setattr__(self, "y", ya)
        object.__setattr__(self, "frequency", f)
        object.__setattr__(self, "source", source)
        object.__setattr__(self, "monostatic", bool(monostatic))
        object.__setattr__(self, "pose", IDENTITY if pose is None else pose)
        object.__setattr__(self, "polarization", pol)
        object.__setattr__(self, "tx_offset", offset)

    def __repr__(self) -> str:
        """A summary (the samples are many): shape, band, grid, kind, source.

        Examples
        --------
        >>> x = np.arange(16) * 0.01
        >>> print(str(Hologram(np.zeros((16, 16)), x, x, 9.9e9)).replace("; ", ";\\n"))
        <holoradar.Hologram (16, 16) complex128: 9.9 GHz;
        x 0 to 15 cm, y 0 to 15 cm (1 x 1 cm);
        receiver array, no source>
        """
        kind = ("line scan along x, " if self.is_line else "") + (
            "transceiver pair (tx_offset)" if self.tx_offset is not None else
            "scanned transceiver" if self.monostatic else "receiver array")
        src = "" if self.monostatic else (
            f", source {type(self.source).__name__}" if self.source is not None
            else ", no source")
        return (f"<holoradar.Hologram {self.data.shape} {self.data.dtype}: "
                f"{_band_text(self.frequencies)}; {_grid_text(self.x, self.y)}; {kind}{src}>")

    @staticmethod
    def from_samples(data: Any, positions: Any, frequency: Any, *, tx: Any = None,
                     monostatic: bool = False, source: Any = None,
                     polarization: Any = None) -> Any:
        """A hologram of samples at scattered positions (a freehand or uneven scan):
        :func:`holoradar.data.samples.from_samples`, which documents the arguments.
        ``migrate`` and ``migration_operator`` image it onto a grid (``x=``, ``y=``).

        Examples
        --------
        >>> rng = np.random.default_rng(0)
        >>> s = Hologram.from_samples(np.ones(200), rng.uniform(0, 0.1, (200, 2)), 10e9,
        ...                           monostatic=True)
        >>> s.n, s.monostatic
        (200, True)
        """
        from .samples import from_samples

        return from_samples(data, positions, frequency, tx=tx, monostatic=monostatic,
                            source=source, polarization=polarization)

    @classmethod
    def from_traces(cls, traces: Any, dt: float, x: Any, *,
                    band: tuple[float, float] | None = None, time_zero: float = 0.0,
                    monostatic: bool = True, **options: Any) -> Hologram:
        """A line scan from time-domain traces (pulse GPR's A-scans).

        Parameters
        ----------
        traces : array_like, real or complex, shape (nt, nx)
            One trace per position (columns), ``nt`` samples in time.
        dt : float
            Sample interval, seconds.
        x : array_like, shape (nx,)
            The positions along the line, metres, monotonic (a line walked backwards
            is reversed with its traces).
        band : (float, float), optional
            ``(f_min, f_max)`` in Hz; default the antenna's, where the traces' mean
            power spectrum is within 10 dB of its peak.
        time_zero : float
            When the pulse leaves the antenna, seconds from the first sample.
        monostatic : bool
            A transceiver (default; a GPR's antenna pair is taken as one).
        **options
            Other :class:`Hologram` options (``pose``, ``polarization``...).

        Returns
        -------
        Hologram
            A line scan (``is_line``) over the band's frequencies
            (:func:`holoradar.data.traces.frequency_samples`: the FFT's bins, the
            sign of ``exp(-i omega t)``, at most 256).

        Examples
        --------
        >>> t = np.arange(512) * 0.1e-9
        >>> traces = np.exp(-((t[:, None] - 3e-9) / 0.3e-9) ** 2) * np.ones((1, 8))
        >>> h = Hologram.from_traces(traces, 0.1e-9, np.arange(8) * 0.02)
        >>> h.is_line, h.monostatic, h.data.shape[1:]
        (True, True, (1, 8))
        """
        from .traces import frequency_samples

        S, f = frequency_samples(traces, dt, band=band, time_zero=time_zero)
        if S.ndim != 2:
            raise ValueError(f"traces must be 2-D, (time samples, positions), got shape "
                             f"{np.shape(traces)}")
        xs = np.asarray(x, dtype=float)
        if xs.ndim != 1 or xs.size != S.shape[1]:
            raise ValueError(f"x must hold one position per trace ({S.shape[1]}), got shape "
                             f"{xs.shape}")
        if xs.size < 2:
            raise ValueError("x: a line scan needs at least 2 positions, got 1")
        steps = np.diff(xs)
        if not (np.all(steps > 0) or np.all(steps < 0)):
            raise ValueError("x must be monotonic (the positions along the line in the order "
                             "walked), got steps of both signs or repeats")
        return cls(S, xs, frequency=f, monostatic=monostatic, **options)

    @property
    def is_vector(self) -> bool:
        """True when both the recorded component and the source's field are vectors: the
        vector model applies."""
        return self.polarization is not None and (self.monostatic
                                                  or has_polarization(self.source))

    @property
    def wavenumbers(self) -> np.ndarray:
        """Wavenumbers in air ``2*pi*f/c`` of every frequency, rad/m (1-D)."""
        return 2 * np.pi * self.frequencies / C0

    def _single(self, what: str) -> float:
        if self.is_wideband:
            raise ValueError(f"this hologram has {self.nf} frequencies: its {what} is not one "
                             f"number (use .frequencies / .wavenumbers, or .at_frequency(i))")
        return float(self.frequency)

    @property
    def wavelength(self) -> float:
        """Wavelength in air, metres (single-frequency holograms)."""
        return C0 / self._single("wavelength")

    @property
    def k(self) -> float:
        """Wavenumber in air, rad/m (single-frequency holograms)."""
        return 2 * np.pi * self._single("wavenumber") / C0

    def at_frequency(self, index: int) -> Hologram:
        """The single-frequency hologram of frequency ``index`` (same geometry).

        Examples
        --------
        >>> x = np.arange(4) * 0.01
        >>> w = Hologram(np.ones((2, 4, 4)), x, x, [9e9, 10e9])
        >>> w.at_frequency(1).frequency
        10000000000.0
        """
        if not self.is_wideband:
            if index not in (0, -1):
                raise ValueError(f"index must be 0 for a single-frequency hologram, got {index}")
            return self
        i = int(index)
        if not -self.nf <= i < self.nf:
            raise ValueError(f"index must be in [0, {self.nf}), got {index}")
        return Hologram(self.data[..., i, :, :], self.x, self.y, float(self.frequencies[i]),
                        source=self.source, monostatic=self.monostatic, pose=self.pose,
                        polarization=self.polarization, tx_offset=self.tx_offset)

    @property
    def shape(self) -> tuple[int, ...]:
        """Shape of ``data``."""
        return self.data.shape

    @cached_property
    def pitch(self) -> tuple[float, float]:
        """``(dx, dy)`` in metres; raises if the grid is not uniform.

        Computed once (the axes are read-only), not at every migration.
        """
        dx = uniform_step(self.x, "x")
        # A line scan's row stands for a strip one pitch wide (its y step taken as x's):
        # the wave fields it images do not vary along y (the 2-D case).
        return dx, (dx if self.is_line else uniform_step(self.y, "y"))

    @property
    def is_line(self) -> bool:
        """True for a line scan (a B-scan): one row of samples along x."""
        return self.y.size == 1

    @property
    def aperture_size(self) -> tuple[float, float]:
        """Full widths ``(A, B)`` = n * pitch, metres."""
        dx, dy = self.pitch
        return self.x.size * dx, self.y.size * dy

    @property
    def points(self) -> np.ndarray:
        """World positions (N, 3) of the elements, metres, row-major over (y, x) like
        ``data`` (on the plane z = 0 for the identity pose)."""
        return self.pose.grid_points(self.x, self.y).reshape(-1, 3)

    def with_data(self, data: Any) -> Hologram:
        """A copy with new ``data`` of the same trailing shape (coordinates kept).

        Examples
        --------
        >>> x = np.arange(4) * 0.01
        >>> Hologram(np.ones((4, 4)), x, x, 1e10).with_data(np.zeros((2, 4, 4))).shape
        (2, 4, 4)
        """
        return Hologram(data, self.x, self.y, self.frequency, source=self.source,
                        monostatic=self.monostatic, pose=self.pose,
                        polarization=self.polarization, tx_offset=self.tx_offset)

    def replace(self, **changes: Any) -> Hologram:
        """A copy with some fields replaced (``dataclasses.replace`` semantics)."""
        kw = {"data": self.data, "x": self.x, "y": self.y, "frequency": self.frequency,
              "source": self.source, "monostatic": self.monostatic, "pose": self.pose,
              "polarization": self.polarization, "tx_offset": self.tx_offset}
        kw.update(changes)
        src, mono, pose = kw.pop("source"), kw.pop("monostatic"), kw.pop("pose")
        pol, offset = kw.pop("polarization"), kw.pop("tx_offset")
        return Hologram(**kw, source=src, monostatic=mono, pose=pose, polarization=pol,
                        tx_offset=offset)


def has_polarization(source: Any) -> bool:
    """True when ``source`` gives a vector field (a Dipole, or a source given a
    ``polarization``)."""
    return getattr(source, "polarization", None) is not None and hasattr(source,
                                                                          "field_vector")


def frequency_axis(frequency: Any, shape: tuple[int, ...]) -> float | np.ndarray:
    """A frequency in Hz, or a strictly increasing axis matching ``shape[-3]``."""
    if np.ndim(frequency) == 0:
        return check_frequency(frequency)
    try:
        f = np.array(frequency, dtype=float)
    except (TypeError, ValueError):
        raise ValueError(f"frequency must be a number in Hz or a 1-D array of them, got "
                         f"{frequency!r}") from None
    if f.ndim != 1 or f.size == 0:
        raise ValueError(f"frequency must be a number in Hz or a 1-D array of them, got shape "
                         f"{f.shape}")
    if not np.all(np.isfinite(f)) or np.any(f <= 0):
        raise ValueError("frequency must hold finite frequencies > 0 in Hz")
    if np.any(np.diff(f) <= 0):
        raise ValueError("frequency must be strictly increasing (sort the frequencies and the "
                         "data's frequency axis together)")
    if len(shape) < 3 or shape[-3] != f.size:
        raise ValueError(f"data must have the frequency axis third from last, (..., {f.size}, "
                         f"ny, nx) for {f.size} frequencies, got shape {shape}")
    f.setflags(write=False)
    return f


@dataclass(frozen=True, eq=False)
class Image:
    """A complex image (reconstructed field) on planes at range ``z``.

    Attributes
    ----------
    data : ndarray, complex
        Shape ``(..., nz, ny, nx)`` for a sequence of ranges, ``(..., ny, nx)``
        for a scalar range.
    x, y : ndarray
        Pixel coordinates, metres.
    z : ndarray
        Ranges of the planes from the aperture, metres (always 1-D).
    frequency : float or ndarray
        Frequency in Hz (the frequencies of a wideband image).
    method : str
        How the image was formed (e.g. ``"angular"``).
    has_z_axis : bool
        True when ``data`` has the ``nz`` axis (a sequence of ranges was asked).
    history : tuple of dict
        What made the image beyond its method, step by step (an inversion's solver,
        its iterations, residual and stop reason); saved with it.

    Examples
    --------
    >>> img = Image(np.zeros((2, 3, 4)), np.arange(4.0), np.arange(3.0), np.array([0.1, 0.2]),
    ...             9.9e9, "angular")
    >>> img.intensity.shape
    (2, 3, 4)
    """

    data: np.ndarray
    x: np.ndarray
    y: np.ndarray
    z: np.ndarray
    frequency: float | np.ndarray
    method: str = "angular"
    has_z_axis: bool = True
    history: tuple = ()

    def __repr__(self) -> str:
        """A summary: shape, ranges, grid, band and how it was made.

        Examples
        --------
        >>> x = np.arange(4) * 0.01
        >>> img = Image(np.zeros((2, 4, 4)), x, x, np.array([0.2, 0.3]), 9.9e9, "angular")
        >>> print(str(img).replace("; ", ";\\n"))
        <holoradar.Image (2, 4, 4) float64: z 20 to 30 cm (2 planes);
        x 0 to 3 cm, y 0 to 3 cm (1 x 1 cm);
        9.9 GHz;
        angular>
        """
        z = np.atleast_1d(np.asarray(self.z, float))
        zt = f"z {z[0] * 100:.4g} cm" if z.size == 1 else \
            f"z {z[0] * 100:.4g} to {z[-1] * 100:.4g} cm ({z.size} planes)"
        f = np.atleast_1d(np.asarray(self.frequency, float)) if self.frequency is not None \
            else np.array([])
        band = _band_text(f) if f.size and np.all(np.isfinite(f)) else "no frequency"
        return (f"<holoradar.Image {np.shape(self.data)} {np.asarray(self.data).dtype}: {zt}; "
                f"{_grid_text(np.atleast_1d(self.x), np.atleast_1d(self.y))}; {band}; "
                f"{self.method or 'image'}>")

    @property
    def intensity(self) -> np.ndarray:
        """``|data|^2``."""
        return np.abs(self.data) ** 2

    def peak(self, unbiased: bool = False, **fit: Any) -> tuple[float, float, float]:
        """``(x, y, z)`` of the brightest voxel over all planes, metres.

        The brightest voxel is not where the object is: along the line of sight the
        image's maximum is pulled towards the array (at one frequency by centimetres).
        The object's own position, from the hologram with its uncertainty (the exact
        point fit under a level array, the inverted reflectivity's strongest object
        under a tilted one), is :func:`holoradar.unbiased_peak`
        ``(image, hologram, medium)``.

        Parameters
        ----------
        unbiased : bool
            Must be False: the fitted position is :func:`holoradar.unbiased_peak`
            (a ``ValueError`` says so).

        Returns
        -------
        tuple of float
            ``(x, y, z)``, metres.

        Examples
        --------
        >>> img = Image(np.zeros((2, 3, 4)), np.arange(4.0), np.arange(3.0),
        ...             np.array([0.1, 0.2]), 9.9e9)
        >>> img.data[1, 2, 3] = 1.0
        >>> img.peak()
        (3.0, 2.0, 0.2)
        """
        if unbiased or fit:
            raise ValueError("Image.peak() is the brightest voxel; the object's fitted "
                             "position is holoradar.unbiased_peak(image, hologram, medium, "
                             "migrate_options)")
        a = np.abs(self.data)
        if not self.has_z_axis:
            a = a[..., None, :, :]
        a = a.reshape((-1, *a.shape[-3:])).max(axis=0)
        iz, iy, ix = np.unravel_index(np.argmax(a), a.shape)
        return float(self.x[ix]), float(self.y[iy]), float(self.z[iz])

    def plane(self, z: float) -> Image:
        """The plane nearest to range ``z`` as a 2-D image.

        Examples
        --------
        >>> img = Image(np.zeros((2, 3, 4)), np.arange(4.0), np.arange(3.0),
        ...             np.array([0.1, 0.2]), 9.9e9)
        >>> img.plane(0.19).data.shape, float(img.plane(0.19).z[0])
        ((3, 4), 0.2)
        """
        if not self.has_z_axis:
            return self
        i = int(np.argmin(np.abs(self.z - z)))
        return replace(self, data=self.data[..., i, :, :], z=self.z[i:i + 1], has_z_axis=False)


def _regular(values: Any, data: np.ndarray, name: str, axis: int) -> tuple[Any, np.ndarray]:
    """:func:`~.grid_axes.regular_axis` where the coordinates are a finite 1-D axis of the
    data's length; anything else as given (``as_axis`` says what is wrong with it)."""
    from .grid_axes import regular_axis

    try:
        v = np.asarray(values, dtype=float)
    except (TypeError, ValueError):
        return values, data
    if v.ndim != 1 or v.size != data.shape[axis] or not np.all(np.isfinite(v)):
        return values, data
    return regular_axis(v, data, name, axis)


def _band_text(f: np.ndarray) -> str:
    """``9.9 GHz``, or ``8 to 12 GHz (11 frequencies)``."""
    if f.size == 1:
        return f"{f[0] / 1e9:.4g} GHz"
    return f"{f[0] / 1e9:.4g} to {f[-1] / 1e9:.4g} GHz ({f.size} frequencies)"


def _grid_text(x: np.ndarray, y: np.ndarray) -> str:
    """``x 0 to 15 cm, y 0 to 15 cm (1 x 1 cm)``: the axes' spans and steps."""
    def span(a: np.ndarray, name: str) -> str:
        return f"{name} {a[0] * 100:.4g}" + (f" to {a[-1] * 100:.4g} cm" if a.size > 1 else " cm")

    def step(a: np.ndarray) -> str:
        return f"{(a[1] - a[0]) * 100:.3g}" if a.size > 1 else "-"

    return f"{span(x, 'x')}, {span(y, 'y')} ({step(x)} x {step(y)} cm)"
