"""The viewer's data and its imaging: holoradar's own functions behind every picture.

A :class:`ViewSession` holds what ``holoradar view`` opened (holograms, one
per view, an image or volume, or a survey store) and answers the page's
questions for a :class:`~holoradar.app.view.settings.ViewSettings`: the
image plane at a depth (:func:`holoradar.migrate` for one view,
:func:`holoradar.synthesize` for several, after
:func:`holoradar.suppress_surface` when the glare is to go), the depth sweep
behind the vertical sections and the shared colour scale, a view's hologram
and its spectral window, the glare's mirror-source plane. The page only draws
what it returns; ``holoradar render`` calls the same methods.

Depth convention: with a ground, ``depth`` is metres below its surface (the
range ``z = surface + depth`` from the array); without one it is the range.
"""

from __future__ import annotations

import warnings
from collections import OrderedDict
from collections.abc import Hashable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from ..._validate import AliasingWarning
from ...data.hologram import Hologram, Image
from ...physics.medium import Medium
from ...physics.sources import PointSource
from .settings import ViewSettings

__all__ = ["GlareSummary", "ViewSession"]


@dataclass(frozen=True)
class GlareSummary:
    """The glare suppression of one view, as the page reports it.

    ``removed_db``: energy of the removed glare over the energy left in the
    hologram, dB; ``direct_db``: the same for the horn's direct wave (None when it
    is kept); ``suppression_db``: the mirror spot's peak before over after, dB;
    ``eps``/``eps_std``: the ground's permittivity estimated from the glare and its
    1-sigma uncertainty (real, imaginary; None where the method gives none);
    ``warning``: what the fit warned about (not converged, an implausible
    reflection); ``error``: why it could not be done. With several frequencies,
    energies are summed over them and the rest is the centre frequency's.
    """

    view: str
    method: str
    removed_db: float | None = None
    suppression_db: float | None = None
    eps: complex | None = None
    eps_std: tuple[float, float] | None = None
    mirror_position: tuple[float, float, float] | None = None
    error: str | None = None
    direct_db: float | None = None
    warning: str | None = None


def _summed_db(left: list[float], removed_db: list[float | None]) -> float | None:
    """Energy removed over energy left, dB, summed over frequencies, from each frequency's
    energy left and its ratio in dB (None when a frequency removed nothing of the kind)."""
    if any(r is None for r in removed_db):
        return None
    gone = sum(e * 10 ** (r / 10) for e, r in zip(left, removed_db, strict=True))  # type: ignore[operator]
    total = sum(left)
    return float(10 * np.log10(gone / total)) if total > 0 and gone > 0 else None


class _Cache:
    """A small least-recently-used cache (the page revisits depths and settings)."""

    def __init__(self, size: int) -> None:
        self.size = size
        self.items: OrderedDict[Hashable, Any] = OrderedDict()

    def get(self, key: Hashable, make: Any) -> Any:
        if key in self.items:
            self.items.move_to_end(key)
            return self.items[key]
        value = make()
        self.items[key] = value
        if len(self.items) > self.size:
            self.items.popitem(last=False)
        return value


def _is_store(path: Path) -> bool:
    from ...survey.store import is_survey

    return path.is_dir() and is_survey(path)


class ViewSession:
    """What the viewer opened, and the imaging behind each picture.

    Parameters
    ----------
    paths : sequence of path
        Holograms (each file one view of the scene, or a file whose leading
        axis holds several views of one source), or one image/volume file, or
        one survey store (``.zarr``): what :func:`holoradar.load` and
        :func:`holoradar.survey.open_survey` open.
    layout, check
        As for :func:`holoradar.load`.

    Raises
    ------
    ValueError
        A file that cannot be read (the reader's message), a mix of kinds, or
        views that do not share one grid and frequency.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> import holoradar as hr
    >>> d = pathlib.Path(tempfile.mkdtemp())
    >>> sand = hr.Medium.half_space(0.3, 2.5)
    >>> scene = hr.Scene(sand, hr.PointSource((0.0, 0.0, -0.05)),
    ...                  [hr.PointTarget((0.0, 0.0, 0.4), 0.05)])
    >>> p = hr.save(hr.simulate(scene, hr.Aperture.grid(16, 0.025), 9.9e9), d / "h.nc")
    >>> s = ViewSession([p])
    >>> look = s.default_settings(ground={"surface": 0.3, "eps": 2.5})
    >>> img = s.image(look.replace(depth=0.1))
    >>> img.data.shape, round(float(img.z[0]), 3)
    ((128, 128), 0.4)
    """

    def __init__(self, paths: Sequence[str | Path], *, layout: Any = None,
                 check: bool = True) -> None:
        from ...io import load

        self.paths = [Path(p) for p in paths]
        if not self.paths:
            raise ValueError("give at least one file to view")
        self.store: Path | None = None
        self.volume: Image | None = None
        self.views: list[Hologram] = []
        self.names: list[str] = []
        if any(_is_store(p) for p in self.paths):
            if len(self.paths) != 1:
                raise ValueError("a survey store is viewed alone: give one .zarr store")
            self.store = self.paths[0]
            self.kind = "survey"
            self._init_survey()
            self._caches()
            return
        for p in self.paths:
            if p.is_dir():
                raise ValueError(f"{p} is a folder, not a holoradar survey store or a file")
            obj = load(p, layout=layout, check=check)
            if isinstance(obj, Image):
                if len(self.paths) != 1:
                    raise ValueError(f"{p.name} holds an image: an image or volume is viewed "
                                     "alone (give holograms to sum several views)")
                self.volume = obj
            else:
                lead = obj.data.shape[:-3 if obj.is_wideband else -2]
                n = int(np.prod(lead)) if lead else 1
                flat = obj.data.reshape((n, *obj.data.shape[len(lead):]))
                for i in range(n):
                    self.views.append(obj.with_data(flat[i]))
                    self.names.append(p.name if n == 1 else f"{p.name}[{i}]")
        self.kind = "image" if self.volume is not None else "holograms"
        if len(self.views) > 1:  # one view needs no source: it is imaged alone
            from ...imaging.synthesis import check_views

            try:
                check_views(self.views)
            except ValueError as exc:
                raise ValueError(f"the files are not views of one scene: {exc}") from None
        self._caches()

    def _caches(self) -> None:
        # Images are cached with what the imaging warned about while making them.
        self._clean = _Cache(8)
        self._planes = _Cache(256)
        self._sweeps = _Cache(4)
        self._objects = _Cache(16)

    def _init_survey(self) -> None:
        from ...survey.reader import open_survey

        ds = open_survey(self.store)
        self.survey_z = np.asarray(ds["z"].values, float)
        self.names = [str(v) for v in ds["frame_name"].values]

    # ------------------------------------------------------------------ the data
    @property
    def frequencies(self) -> np.ndarray:
        """The frequencies of the views (Hz); an image's or a survey's: empty."""
        return self.views[0].frequencies if self.views else np.array([])

    @property
    def tilted(self) -> bool:
        """True when the views come from a tilted array (imaged on level planes)."""
        return bool(self.views) and not self.views[0].pose.is_level

    def default_settings(self, ground: Any = None, **changes: Any) -> ViewSettings:
        """Settings that show the data at once: all views, the peak's depth later.

        ``ground`` is a table as in a scene file (``{"surface": 0.3, "eps": 2.5}``).
        """
        files = tuple(str(p) for p in self.paths)
        if ground is None:
            sweep = (0.1, 0.8)
        else:
            sweep = (0.0, 0.25)
        s = ViewSettings(files=files, ground=ground, sweep=sweep,
                         frame="ground" if self.tilted else "aperture")
        if self.volume is not None:
            z = self.volume.z
            s = s.replace(ground=None, sweep=(float(z.min()), float(max(z.max(), z.min() + 1e-6))),
                          depth=float(z[len(z) // 2]), planes=max(2, int(z.size)))
        elif self.store is not None:
            z = self.survey_z
            s = s.replace(ground=None, sweep=(float(z.min()), float(max(z.max(), z.min() + 1e-6))),
                          depth=float(z[0]), planes=max(2, int(z.size)))
        return s.replace(**changes)

    def opening_settings(self, s: ViewSettings, *, glare: bool = True,
                         depth: bool = True) -> ViewSettings:
        """The look the viewer opens with: the object, not the glare.

        Raw holograms over ground are mostly the surface glare (the horn's
        reflection): its speckle fills the planes near the surface and its focus
        is the brightest point of the sweep. So, for holograms whose sweep's
        brightest point is the glare (the dominance check of ``holoradar image``),
        the glare is removed (the Gaussian-beam fit, the fast one) when it can be:
        the look has a ground, every view's radiator is known and point-like (a
        horn, a dipole, a Gaussian beam) and every fit succeeds. Data without glare
        (removed before, or an object brighter than it) open as they are. The
        depth is that of the brightest point of the sweep so imaged.

        Parameters
        ----------
        s : ViewSettings
            The look so far (:meth:`default_settings`, with what the user gave).
        glare : bool
            Choose the glare suppression (False: the user chose it).
        depth : bool
            Choose the depth (False: the user gave one).

        Returns
        -------
        ViewSettings
            ``s`` for an image or a survey.

        Examples
        --------
        >>> import tempfile, pathlib
        >>> import holoradar as hr
        >>> d = pathlib.Path(tempfile.mkdtemp())
        >>> sand = hr.Medium.half_space(0.3, 2.5)
        >>> scene = hr.Scene(sand, hr.PointSource((0.0, -0.2, -0.05)),
        ...                  [hr.PointTarget((0.0, 0.0, 0.4), 0.01)])
        >>> ap, ground = hr.Aperture.grid(16, 0.025), {"surface": 0.3, "eps": 2.5}
        >>> p = hr.save(hr.simulate(scene, ap, 9.9e9), d / "h.nc")
        >>> session = ViewSession([p])
        >>> look = session.opening_settings(session.default_settings(ground))
        >>> look.glare, bool(0.0 < look.depth < 0.2)   # the object 10 cm deep, not the surface
        ('gaussian', True)
        >>> q = hr.save(hr.simulate(scene, ap, 9.9e9, include_surface=False), d / "q.nc")
        >>> session = ViewSession([q])   # no glare in the data: nothing to remove
        >>> session.opening_settings(session.default_settings(ground)).glare
        'off'
        """
        if self.kind != "holograms":
            return s
        if glare and s.glare == "off" and self._glare_removable(s) and self._glare_shows(s):
            on = s.replace(glare="gaussian")
            _, notes = self.cleaned(on)
            if all(n.error is None for n in notes):
                s = on
        if depth:
            from ...analysis.metrics import peak_position

            s = s.replace(depth=float(peak_position(self.sweep(s))[2] - self.surface(s)))
        return s

    def _glare_shows(self, s: ViewSettings) -> bool:
        """Whether the raw sweep's brightest point is the surface glare (the dominance
        check of ``holoradar image``) in the first view at its centre frequency; where
        that cannot be told, True (the glare is the rule over ground). Data without glare
        (removed before, or none) open as they are."""
        from ...imaging.glare.dominance import glare_share
        from ...imaging.migrate import migrate

        h = self.views[0]
        if h.is_wideband:
            h = h.at_frequency(h.nf // 2)
        a, b = s.sweep if s.sweep is not None else (0.0, 0.25)
        zs = self.surface(s) + np.linspace(a, b, s.planes)
        opts = {"upsample": s.upsample, "fov": s.fov if s.frame == "aperture" else "aperture"}
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                img = migrate(h, zs, medium=self.medium(s), **opts)
                found = glare_share(h, img, self.medium(s), **opts)
        except ValueError:
            return True
        return True if found is None else bool(found.dominates)

    def _glare_removable(self, s: ViewSettings) -> bool:
        """Whether ``s`` has a ground and every view a known point-like radiator."""
        from ...imaging.glare._common import Radiator

        if self.medium(s) is None:
            return False
        return all(not h.monostatic and isinstance(h.source, Radiator) for h in self.views)

    def medium(self, s: ViewSettings) -> Medium | None:
        """The ground of ``s`` at the views' (centre) frequency; None: free space."""
        if s.ground is None or self.kind != "holograms":
            return None
        from ...model.scene_file import medium_from_mapping

        return medium_from_mapping(s.ground, float(np.mean(self.frequencies)), where="ground")

    def surface(self, s: ViewSettings) -> float:
        """Range of the ground surface (0 without a ground): depth = z - surface."""
        m = self.medium(s)
        return 0.0 if m is None or m.is_free_space else float(m.z_interfaces[0])

    def selected(self, s: ViewSettings) -> list[int]:
        """Indices of the views summed (checked against what was opened)."""
        n = len(self.views)
        use = list(range(n)) if s.views is None else list(s.views)
        bad = [i for i in use if i >= n]
        if bad:
            raise ValueError(f"views.use: view {bad[0]} does not exist: {n} view(s) opened "
                             f"(0 to {n - 1})")
        return use

    # ----------------------------------------------------------------- glare
    def _glare_key(self, s: ViewSettings) -> tuple[Any, ...]:
        return (repr(s.ground), s.glare, s.direct, s.frequency)

    def cleaned(self, s: ViewSettings) -> tuple[list[Hologram], list[GlareSummary]]:
        """Every view at the chosen frequency, its glare removed when ``s.glare`` asks.

        A view whose glare cannot be removed (no ground, a plane-wave source)
        stays as it is; its summary says why.
        """
        return self._clean.get(self._glare_key(s), lambda: self._make_clean(s))

    def _at_frequency(self, h: Hologram, s: ViewSettings) -> Hologram:
        if isinstance(s.frequency, int) and not isinstance(s.frequency, bool):
            if not h.is_wideband:
                if s.frequency != 0:
                    raise ValueError(f"views.frequency: index {s.frequency} does not exist: "
                                     "the data hold one frequency (index 0)")
                return h
            if s.frequency >= h.nf:
                raise ValueError(f"views.frequency: index {s.frequency} does not exist: "
                                 f"{h.nf} frequencies (0 to {h.nf - 1})")
            return h.at_frequency(s.frequency)
        return h

    def _make_clean(self, s: ViewSettings) -> tuple[list[Hologram], list[GlareSummary]]:
        from ...imaging.glare import suppress_surface

        views = [self._at_frequency(h, s) for h in self.views]
        if s.glare == "off":
            return views, []
        medium = self.medium(s)
        out, notes = [], []
        for name, h in zip(self.names, views, strict=True):
            if medium is None:
                out.append(h)
                notes.append(GlareSummary(name, s.glare, error="the glare needs a ground: set "
                                          "its surface and permittivity"))
                continue
            try:
                with warnings.catch_warnings(record=True) as said:
                    warnings.simplefilter("always")
                    if h.is_wideband:  # one fit per frequency: the glare's phase moves with f
                        # eps (exact fit, with its sigma) from the middle frequency's,
                        # the one the table shows
                        parts = [suppress_surface(h.at_frequency(i), medium, method=s.glare,
                                                  direct=s.direct,
                                                  exact_eps=s.glare == "gaussian"
                                                  and i == h.nf // 2)
                                 for i in range(h.nf)]
                        clean = h.with_data(np.stack([c.data for c, _ in parts], axis=-3))
                        rep = parts[h.nf // 2][1]
                        left = [float(np.linalg.norm(c.data)) ** 2 for c, _ in parts]
                        removed = _summed_db(left, [r.glare_removed_db for _, r in parts])
                        direct = _summed_db(left, [r.direct_removed_db for _, r in parts])
                    else:
                        clean, rep = suppress_surface(h, medium, method=s.glare,
                                                      direct=s.direct,
                                                      exact_eps=s.glare == "gaussian")
                        removed, direct = rep.glare_removed_db, rep.direct_removed_db
            except ValueError as exc:
                out.append(h)
                notes.append(GlareSummary(name, s.glare, error=str(exc)))
                continue
            heard = sorted({str(w.message) for w in said
                            if not issubclass(w.category, AliasingWarning)})
            out.append(clean)
            notes.append(GlareSummary(name, s.glare, removed_db=removed, direct_db=direct,
                                      suppression_db=rep.glare_suppression_db, eps=rep.eps,
                                      eps_std=rep.eps_std,
                                      mirror_position=rep.mirror_position,
                                      warning="; ".join(heard) or None))
        return out, notes

    # ----------------------------------------------------------------- images
    def _form(self, s: ViewSettings, z: Any) -> tuple[Image, tuple[str, ...]]:
        """The image of the selected views at range(s) ``z``, and what the imaging warned
        about (an assumed illumination, say; the aliasing of the array's pitch is known
        and said in the page's info)."""
        from ...imaging.migration.image import image_of
        from ...imaging.synthesis import synthesize

        views, _ = self.cleaned(s)
        use = [views[i] for i in self.selected(s)]
        medium = self.medium(s)
        how = s.migration()
        kw: dict[str, Any] = {"upsample": how.upsample, "frame": how.frame}
        if how.frame == "aperture":
            kw["fov"] = how.fov
        with warnings.catch_warnings(record=True) as said:
            warnings.simplefilter("always")
            if s.plane == "reflectivity":
                img = self._reflectivity(use, z, medium, how)
            elif len(use) == 1:
                img = image_of(use[0], z, medium, how)
            elif how.combine == "incoherent" and use[0].is_wideband:
                raise ValueError("views.frequency: the incoherent sum of frequencies is "
                                 "for one view; several views add their coherent images "
                                 "(choose 'coherent' or one frequency)")
            else:
                img = synthesize(use, z, medium=medium, mode=s.mode, **kw)
        return img, tuple(sorted({str(w.message) for w in said
                                  if not issubclass(w.category, AliasingWarning)}))

    @staticmethod
    def _reflectivity(use: list[Hologram], z: Any, medium: Any, how: Any) -> Image:
        """One view's reflectivity (:func:`holoradar.invert`, damped least squares
        stopped at the noise: the illumination divided out, each voxel's Born
        amplitude) on the look's planes and pixels, the aperture's field of view."""
        from ...imaging.inversion.api import invert

        if len(use) != 1:
            raise ValueError("display.plane: the reflectivity inverts one view's hologram; "
                             "choose one view (views.use)")
        return invert(use[0], z, medium=medium, progress=False, upsample=how.upsample,
                      frame=how.frame)

    def _key(self, s: ViewSettings) -> tuple[Any, ...]:
        return (self._glare_key(s), s.views, s.mode, s.upsample, s.fov, s.frame,
                s.plane == "reflectivity")

    def image(self, s: ViewSettings, depth: float | None = None) -> Image:
        """The plane shown for ``s`` (at ``depth``, default ``s.depth``), 2-D complex.

        ``s.plane == "mirror"`` gives the glare's mirror-source plane instead
        (:meth:`mirror_plane`). An image file gives its nearest plane; a survey
        the mosaic of its frames (amplitude).
        """
        d = s.depth if depth is None else float(depth)
        if self.volume is not None:
            return self.volume.plane(d)
        if self.store is not None:
            from ...survey.mosaic import mosaic

            return self._planes.get(("mosaic", d), lambda: mosaic(self.store, d))
        if s.plane == "mirror":
            return self.mirror_plane(s)
        if s.plane == "reflectivity":
            # A plane of the sweep's inversion: inverted alone, a plane would be made to
            # explain what lies above and below it (one frequency's long focus).
            return self.sweep(s).plane(self.surface(s) + d)
        z = self.surface(s) + d
        return self._planes.get((self._key(s), round(z, 12)), lambda: self._form(s, z))[0]

    def sweep(self, s: ViewSettings) -> Image:
        """The volume behind the sections and the colour scale: ``s.planes`` planes over
        ``s.sweep`` (depths)."""
        if self.volume is not None:
            return self.volume
        if self.store is not None:  # every plane of the store's mosaic: one colour scale
            def stack() -> Image:
                planes = [self.image(s, float(z)) for z in self.survey_z]
                p0 = planes[0]
                return Image(np.stack([p.data for p in planes]), p0.x, p0.y,
                             self.survey_z.copy(), p0.frequency, p0.method)

            return self._sweeps.get(("mosaic",), stack)
        return self._swept(s)[0]

    def _swept(self, s: ViewSettings) -> tuple[Image, tuple[str, ...]]:
        a, b = s.sweep if s.sweep is not None else (0.0, 0.25)
        zs = self.surface(s) + np.linspace(a, b, s.planes)
        return self._sweeps.get((self._key(s), a, b, s.planes), lambda: self._form(s, zs))

    def notes(self, s: ViewSettings) -> tuple[str, ...]:
        """What the imaging warned about for ``s`` (its depth sweep's warnings: the same
        views, ground and settings as each plane); empty for an image or a survey."""
        return self._swept(s)[1] if self.kind == "holograms" else ()

    def mirror_source(self, s: ViewSettings) -> tuple[int, float]:
        """The view whose glare is shown (the first selected) and its mirror plane's range
        ``z_m = 2 z0 - z_s`` (metres)."""
        medium = self.medium(s)
        i = self.selected(s)[0]
        src = self.views[i].source
        if medium is None:
            raise ValueError("the mirror-source plane needs a ground: set its surface")
        if not isinstance(src, PointSource):
            raise ValueError(f"{self.names[i]}: the mirror-source plane needs a point "
                             "radiator (a plane wave's glare does not focus)")
        if not self.views[i].pose.is_identity:
            raise ValueError(f"{self.names[i]}: the mirror-source plane is shown for an "
                             "array at z = 0 facing the ground")
        return i, 2 * float(medium.z_interfaces[0]) - float(src.position[2])

    def mirror_plane(self, s: ViewSettings) -> Image:
        """The first selected view back-propagated in air to its mirror-source plane, where
        the surface glare focuses (after suppression when ``s.glare`` is on)."""
        from ...imaging.migration.image import image_of

        i, zm = self.mirror_source(s)
        views, _ = self.cleaned(s)

        def make() -> Image:
            # in the array's own frame: mirror_source took an array facing the ground
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                return image_of(views[i], zm, None, s.migration().replace(
                    frame="aperture", fov=s.fov, combine="coherent"))

        return self._planes.get(("mirror", self._glare_key(s), i, s.upsample, s.fov), make)

    def objects(self, s: ViewSettings) -> Any:
        """The objects in the plane shown for ``s``: :func:`holoradar.detect` on it, with
        the look's ground (depths below its surface; none without a ground).

        Returns
        -------
        pandas.DataFrame
            detect's table (cached per plane and look).

        Raises
        ------
        ValueError
            The mirror-source plane (the glare's focus, not the scene), or what
            detect refuses.
        """
        if self.kind == "holograms" and s.plane == "mirror":
            raise ValueError("objects are found in the image plane, not the mirror-source "
                             "plane: choose 'image plane'")
        if self.kind == "holograms":
            key: tuple[Any, ...] = (self._key(s), round(self.surface(s) + s.depth, 12))
        else:
            key = (self.kind, round(s.depth, 12))

        def find() -> Any:
            from ...analysis.detect import detect

            with warnings.catch_warnings():
                warnings.simplefilter("ignore", AliasingWarning)
                return detect(self.image(s), medium=self.medium(s))

        return self._objects.get(key, find)

    def hologram(self, s: ViewSettings, view: int) -> Hologram:
        """One view as imaged (chosen frequency, glare removed if asked), 2-D: a wideband
        view shows its centre frequency."""
        views, _ = self.cleaned(s)
        h = views[view]
        return h.at_frequency(h.nf // 2) if h.is_wideband else h

    def spectrum(self, s: ViewSettings, view: int) -> tuple[np.ndarray, np.ndarray,
                                                             np.ndarray]:
        """The spectral window of a view: ``(kx/k, ky/k, |FFT|)`` of its hologram (zero
        padded 4 times), centred; ``|kx/k|, |ky/k| <= 1`` are the waves that travel."""
        import scipy.fft as sfft

        h = self.hologram(s, view)
        ny, nx = h.data.shape[-2:]
        m = (4 * ny, 4 * nx)
        spec = np.abs(sfft.fftshift(sfft.fft2(h.data, s=m)))
        dx, dy = h.pitch
        kx = sfft.fftshift(sfft.fftfreq(m[1], dx)) * 2 * np.pi / h.k
        ky = sfft.fftshift(sfft.fftfreq(m[0], dy)) * 2 * np.pi / h.k
        return kx, ky, spec
