"""Speed of migration against the bare FFTs it needs and against peer libraries.

Ratios are measured in one run on the same machine (wall-clock figures on a
shared machine are noisy; ratios much less so). The two sides of each ratio are
timed interleaved, ``REPEAT`` times each after a warm-up (transfer functions
cached, FFT plans warm), and the fastest run of each is kept: noise from other
work on a shared machine only ever adds time.

Run: ``make bench`` (installs the optional peers LightPipes and diffractsim).
Writes ``benchmarks/results.json`` and prints a Markdown table.
"""

from __future__ import annotations

import json
import time
import warnings
from collections.abc import Callable
from pathlib import Path

import numpy as np
import scipy.fft as sfft

import holoradar as hr

N = 512
PLANES = 64
REPEAT = 40
F0 = 9.9e9
LAM = hr.C0 / F0
DX = LAM / 2


def best_times(*fns: Callable[[], object], repeat: int = REPEAT) -> list[float]:
    """Fastest of ``repeat`` interleaved runs of each function, seconds."""
    for fn in fns:
        fn()  # warm-up: plans, caches
    best = [np.inf] * len(fns)
    for _ in range(repeat):
        for i, fn in enumerate(fns):
            t0 = time.perf_counter()
            fn()
            best[i] = min(best[i], time.perf_counter() - t0)
    return best


def main() -> dict:
    rng = np.random.default_rng(0)
    field = (rng.standard_normal((N, N)) + 1j * rng.standard_normal((N, N))).astype(np.complex64)
    x = (np.arange(N) - N / 2) * DX
    holo = hr.Hologram(field, x, x, F0)
    zs = np.linspace(0.2, 0.6, PLANES)
    res: dict[str, float | str] = {"n": N, "planes": PLANES, "dtype": "complex64"}

    # Bare FFTs (scipy.fft, all cores): the floor the migration cannot beat.
    a = field.copy()
    big = np.zeros((2 * N, 2 * N), np.complex64)
    stack = np.zeros((PLANES, N, N), np.complex64)

    def pair() -> object:
        return sfft.ifft2(sfft.fft2(a, workers=-1), workers=-1)

    def pair_pad() -> object:
        return sfft.ifft2(sfft.fft2(big, workers=-1), workers=-1)

    def volume_ffts() -> object:  # one forward FFT, then 64 inverse FFTs into 64 planes
        sfft.fft2(a, workers=-1)
        return sfft.ifft2(stack, axes=(-2, -1), workers=-1)

    work = field.copy()
    work_big = big.copy()
    work_stack = stack.copy()

    def pair_in_place() -> object:  # the tight floor: no allocation at all
        sfft.fft2(work, workers=-1, overwrite_x=True)
        return sfft.ifft2(work, workers=-1, overwrite_x=True)

    def pair_pad_in_place() -> object:
        sfft.fft2(work_big, workers=-1, overwrite_x=True)
        return sfft.ifft2(work_big, workers=-1, overwrite_x=True)

    def volume_in_place() -> object:  # one batched in-place inverse FFT of all planes
        return sfft.ifft2(work_stack, axes=(-2, -1), workers=-1, overwrite_x=True)

    t_tight, t_tight_pad, t_tight_vol = best_times(pair_in_place, pair_pad_in_place,
                                                   volume_in_place, repeat=7)
    # Cold: a new frequency each call (no cached transfer function).
    freqs = iter(F0 * (1 + 1e-6 * np.arange(1, 1000)))

    def cold() -> object:
        return hr.migrate(hr.Hologram(field, x, x, next(freqs)), 0.4, pad=False)

    def cold_volume() -> object:
        return hr.migrate(hr.Hologram(field, x, x, next(freqs)), zs, pad=False)

    t_pair, t_plane = best_times(pair, lambda: hr.migrate(holo, 0.4, pad=False))
    (t_cold,) = best_times(cold, repeat=7)
    (t_cold_vol,) = best_times(cold_volume, repeat=3)
    t_pair_pad, t_plane_pad = best_times(pair_pad, lambda: hr.migrate(holo, 0.4, pad=True))
    t_ffts, t_volume = best_times(volume_ffts, lambda: hr.migrate(holo, zs, pad=False),
                                  repeat=7)
    res.update({
        "fft_pair_s": t_pair, "plane_s": t_plane, "plane_over_pair": t_plane / t_pair,
        "fft_pair_padded_s": t_pair_pad, "plane_padded_s": t_plane_pad,
        "plane_padded_over_pair_padded": t_plane_pad / t_pair_pad,
        "volume_s": t_volume, "volume_ffts_s": t_ffts, "volume_over_ffts": t_volume / t_ffts,
        "fft_pair_in_place_s": t_tight, "plane_over_in_place_pair": t_plane / t_tight,
        "fft_pair_padded_in_place_s": t_tight_pad,
        "plane_padded_over_in_place_pair": t_plane_pad / t_tight_pad,
        "volume_ifft_in_place_s": t_tight_vol, "volume_over_in_place": t_volume / t_tight_vol,
        "cold_plane_s": t_cold, "cold_plane_over_pair": t_cold / t_pair,
        "cold_volume_s": t_cold_vol, "cold_volume_over_ffts": t_cold_vol / t_ffts,
    })
    plane, pair_t = t_plane, t_pair

    # Peers, same grid and distance, their default settings.
    try:
        import LightPipes

        F = LightPipes.Begin(N * DX, LAM, N)
        F.field = field.astype(complex)
        t, plane = best_times(lambda: LightPipes.Forvard(F, 0.4),
                              lambda: hr.migrate(holo, 0.4, pad=False))
        res.update({"lightpipes_forvard_s": t, "lightpipes_over_plane": t / plane,
                    "lightpipes_over_pair": t / pair_t})
    except ImportError:
        res["lightpipes_forvard_s"] = "not installed (make bench installs it)"
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            from diffractsim import MonochromaticField

            def ds() -> None:
                fld = MonochromaticField(LAM, N * DX, N * DX, N, N)
                fld.E = field.astype(complex)
                fld.propagate(0.4)

            t, plane = best_times(ds, lambda: hr.migrate(holo, 0.4, pad=False))
        res.update({"diffractsim_propagate_s": t, "diffractsim_over_plane": t / plane,
                    "diffractsim_over_pair": t / pair_t})
    except ImportError:
        res["diffractsim_propagate_s"] = "not installed (make bench installs it)"
    return res


def table(r: dict) -> str:
    def f(key: str) -> str:
        v = r.get(key)
        return f"{v * 1e3:.2f} ms" if isinstance(v, float) else str(v)

    rows = [
        ("one plane, 512^2, no padding", f("plane_s"), f("fft_pair_s"),
         f"{r['plane_over_pair']:.2f}x fft2+ifft2"),
        ("one plane, padded to 1024^2", f("plane_padded_s"), f("fft_pair_padded_s"),
         f"{r['plane_padded_over_pair_padded']:.2f}x fft2+ifft2 at 1024^2"),
        (f"{PLANES}-plane volume", f("volume_s"), f("volume_ffts_s"),
         f"{r['volume_over_ffts']:.2f}x (1 fft2 + {PLANES} ifft2)"),
        ("one plane, 512^2, vs in-place pair", f("plane_s"), f("fft_pair_in_place_s"),
         f"{r['plane_over_in_place_pair']:.2f}x in-place fft2+ifft2"),
        ("one plane padded, vs in-place pair", f("plane_padded_s"),
         f("fft_pair_padded_in_place_s"),
         f"{r['plane_padded_over_in_place_pair']:.2f}x in-place pair at 1024^2"),
        (f"{PLANES}-plane volume, vs in-place", f("volume_s"), f("volume_ifft_in_place_s"),
         f"{r['volume_over_in_place']:.2f}x one batched in-place ifft2"),
        ("cold plane (new frequency)", f("cold_plane_s"), f("fft_pair_s"),
         f"{r['cold_plane_over_pair']:.2f}x fft2+ifft2"),
        (f"cold {PLANES}-plane volume", f("cold_volume_s"), f("volume_ffts_s"),
         f"{r['cold_volume_over_ffts']:.2f}x its FFTs"),
    ]
    for peer, key in (("LightPipes Forvard", "lightpipes"), ("diffractsim propagate",
                                                                "diffractsim")):
        if f"{key}_over_plane" in r:
            rows.append((peer, f(f"{key}_forvard_s" if key == "lightpipes"
                                 else f"{key}_propagate_s"), f("fft_pair_s"),
                         f"{r[f'{key}_over_pair']:.1f}x pair; holoradar is "
                         f"{r[f'{key}_over_plane']:.1f}x faster"))
    out = ["| case | time | bare FFTs | ratio |", "|---|---|---|---|"]
    out += [f"| {a} | {b} | {c} | {d} |" for a, b, c, d in rows]
    return "\n".join(out)


if __name__ == "__main__":
    r = main()
    Path(__file__).with_name("results.json").write_text(json.dumps(r, indent=2))
    print(table(r))
