"""Inputs and checks for ``tests/gl/test_stability.py`` (issue 4, docs/design.md §5 and §8).

- ``EXTREMES``: one material per end of every range of docs/design.md §5, each named
  (``ex=1e6``, ``theta1=-2pi``, ``mu_f=0`` ...);
- ``DEGENERATE``: the degenerate geometry of docs/design.md §8 as named (n, t, l, v)
  cases;
- ``random_cases`` / ``lobe_cases``: generic shading cases, the second aimed at
  the specular lobe at every width from 1e-4 to 1 (so that exponents up to 1e6
  are sampled where they are not zero);
- ``probe_error`` / ``check_probe`` / ``plot_bound``: the agreement measures
  against the float64 reference;
- ``isolated_spikes`` / ``fireflies``: the firefly detector.
"""

from __future__ import annotations

import math
import warnings

import numpy as np

from opaline.model import reference as ref
from opaline.model.params import Material

PI = math.pi
TWO_PI = 2.0 * math.pi

# (1) MDF plot: max |gl - ref| within 1e-4 of the plot's peak, or 1e-6 absolute
# where the peak itself is ~0 (an A-S lobe narrower than the pixel grid).
PLOT_TOLERANCE = 1e-4
PLOT_FLOOR = 1e-6
# (2) BRDF probe: |gl - ref| <= 2e-3 · (|ref| + 1e-3 · max|ref|), per case and channel.
PROBE_RTOL = 2e-3
PROBE_FLOOR = 1e-3
# Fireflies: a pixel brighter than 20× the median of its 8 neighbours with no
# neighbour within that factor of it.
SPIKE_RATIO = 20.0


# -- materials ----------------------------------------------------------------

ASHIKHMIN = {"mdf": "ashikhmin", "ex": 100.0, "ey": 10.0, "theta1": 0.2, "theta2": 0.4}
MULTIPEAK = {"mdf": "multipeak", "mu_f": 8.5, "alpha": 2.0, "beta": 1.2, "theta1": 0.1, "theta2": 0.2}

ANGLES = {
    "-2pi": -TWO_PI, "-3pi/2": -1.5 * PI, "-pi": -PI, "-pi/2": -0.5 * PI, "-0.3": -0.3,
    "-1e-6": -1e-6, "0": 0.0, "1e-6": 1e-6, "pi/2": 0.5 * PI, "pi": PI, "3pi/2": 1.5 * PI,
    "2pi": TWO_PI,
}


def material(base: dict, **changes) -> Material:
    """A validated Material: ``base`` with ``changes`` (Material rejects out-of-range values)."""
    return Material(**{**base, **changes})


def _extremes() -> dict[str, Material]:
    found: dict[str, Material] = {}

    def add(name: str, base: dict, **changes) -> None:
        assert name not in found, name
        found[name] = material(base, **changes)

    # Ashikhmin-Shirley exponents, 0 ... 1e6.
    for label, value in {"0": 0.0, "1e-6": 1e-6, "1e-3": 1e-3, "1e6": 1e6}.items():
        add(f"ex={label}", ASHIKHMIN, ex=value)
        add(f"ey={label}", ASHIKHMIN, ey=value)
    add("ex=ey=0", ASHIKHMIN, ex=0.0, ey=0.0)
    add("ex=ey=1e-6", ASHIKHMIN, ex=1e-6, ey=1e-6)
    add("ex=ey=1e6", ASHIKHMIN, ex=1e6, ey=1e6)
    add("ex=0,ey=1e6", ASHIKHMIN, ex=0.0, ey=1e6)
    add("ex=1e6,ey=0", ASHIKHMIN, ex=1e6, ey=0.0)
    add("ex=1e6,ey=1e-6", ASHIKHMIN, ex=1e6, ey=1e-6)
    # Multi-peak frequency and anisotropy, 0 ... 1000.
    for label, value in {"0": 0.0, "1e-6": 1e-6, "1e-3": 1e-3, "1000": 1000.0}.items():
        add(f"mu_f={label}", MULTIPEAK, mu_f=value)
        add(f"alpha={label}", MULTIPEAK, alpha=value)
        add(f"beta={label}", MULTIPEAK, beta=value)
    add("alpha=beta=0", MULTIPEAK, alpha=0.0, beta=0.0)
    add("alpha=beta=1e-6", MULTIPEAK, alpha=1e-6, beta=1e-6)
    add("mu_f=0,alpha=beta=1000", MULTIPEAK, mu_f=0.0, alpha=1000.0, beta=1000.0)
    add("mu_f=1000,alpha=beta=0", MULTIPEAK, mu_f=1000.0, alpha=0.0, beta=0.0)
    add("mu_f=1000,alpha=1000,beta=0", MULTIPEAK, mu_f=1000.0, alpha=1000.0, beta=0.0)
    add("mu_f=alpha=beta=1000", MULTIPEAK, mu_f=1000.0, alpha=1000.0, beta=1000.0)
    # Rotations, -2π ... 2π, on both MDFs (the A-S lobe is anisotropic: ex 100, ey 10).
    for mdf, base in (("ashikhmin", ASHIKHMIN), ("multipeak", MULTIPEAK)):
        for label, value in ANGLES.items():
            add(f"{mdf}:theta1={label}", base, theta1=value)
            add(f"{mdf}:theta2={label}", base, theta2=value)
        add(f"{mdf}:theta1=2pi,theta2=-2pi", base, theta1=TWO_PI, theta2=-TWO_PI)
        add(f"{mdf}:theta1=-2pi,theta2=2pi", base, theta1=-TWO_PI, theta2=TWO_PI)
    # Weights, albedo and Fresnel (the variant compiles DIFFUSE / FRESNEL in or out).
    for mdf, base in (("ashikhmin", ASHIKHMIN), ("multipeak", MULTIPEAK)):
        for label, value in {"0": 0.0, "1e-6": 1e-6, "100": 100.0}.items():
            add(f"{mdf}:kd={label}", base, kd=value)
            add(f"{mdf}:ks={label}", base, ks=value)
        add(f"{mdf}:kd=ks=0", base, kd=0.0, ks=0.0)
        add(f"{mdf}:kd=ks=100", base, kd=100.0, ks=100.0, albedo=(1.0, 1.0, 1.0))
        add(f"{mdf}:albedo=0", base, kd=1.0, albedo=(0.0, 0.0, 0.0))
        add(f"{mdf}:albedo=1", base, kd=1.0, albedo=(1.0, 1.0, 1.0))
        add(f"{mdf}:albedo=(1,0,0)", base, kd=1.0, albedo=(1.0, 0.0, 0.0))
        for label, value in {"0": 0.0, "1e-6": 1e-6, "0.5": 0.5, "1": 1.0}.items():
            add(f"{mdf}:f0={label}", base, f0=value)
    # A clear coat over both MDFs, at the ends of its weight, roughness and index (issue 23).
    for mdf, base in (("ashikhmin", ASHIKHMIN), ("multipeak", MULTIPEAK)):
        add(f"{mdf}:coat=1,rough=0", base, coat_weight=1.0, coat_roughness=0.0)
        add(f"{mdf}:coat=1,rough=1,ior=3", base, coat_weight=1.0, coat_roughness=1.0,
            coat_ior=3.0)
        add(f"{mdf}:coat=1e-6,ior=1", base, coat_weight=1e-6, coat_ior=1.0)
    # Everything at an end at once.
    add("ashikhmin:all-max", ASHIKHMIN, ex=1e6, ey=1e6, theta1=TWO_PI, theta2=-TWO_PI,
        kd=100.0, ks=100.0, albedo=(1.0, 1.0, 1.0), f0=0.0, coat_weight=1.0, coat_ior=3.0)
    add("ashikhmin:all-min", ASHIKHMIN, ex=0.0, ey=0.0, theta1=-TWO_PI, theta2=0.0,
        kd=0.0, ks=1e-6, albedo=(0.0, 0.0, 0.0), f0=0.0)
    add("multipeak:all-max", MULTIPEAK, mu_f=1000.0, alpha=1000.0, beta=1000.0, theta1=TWO_PI,
        theta2=-TWO_PI, kd=100.0, ks=100.0, albedo=(1.0, 1.0, 1.0), f0=0.0)
    add("multipeak:all-min", MULTIPEAK, mu_f=0.0, alpha=0.0, beta=0.0, theta1=-TWO_PI,
        theta2=0.0, kd=0.0, ks=1e-6, albedo=(0.0, 0.0, 0.0), f0=0.0)
    return found


EXTREMES: dict[str, Material] = _extremes()


# -- shading cases --------------------------------------------------------------

def as_f32(a) -> np.ndarray:
    """What the GPU is given: float32 values, here back in float64 for the reference."""
    return np.asarray(a, dtype=np.float32).astype(np.float64)


def unit(v) -> np.ndarray:
    v = np.asarray(v, dtype=np.float64)
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def random_unit(rng: np.random.Generator, count: int) -> np.ndarray:
    return unit(rng.normal(size=(count, 3)))


def random_cases(rng: np.random.Generator, count: int):
    """Random frames with l and v in the upper hemisphere of n."""
    n, t, l, v = (random_unit(rng, count) for _ in range(4))
    l *= np.sign(np.sum(l * n, axis=1, keepdims=True))
    v *= np.sign(np.sum(v * n, axis=1, keepdims=True))
    return n, t, l, v


def lobe_cases(rng: np.random.Generator, count: int):
    """Mirror configurations with h at tan-angle 1e-4 ... 1 (log-uniform) from n.

    Random cases almost never land in an A-S lobe of exponent 1e5-1e6 (width
    ~1e-3); these put h at every distance from the pole, in every direction of
    the tangent plane, with l and v both above the surface.
    """
    n = random_unit(rng, 4 * count)
    t_in = random_unit(rng, 4 * count)
    t, b, n = ref.shading_frame(n, t_in)
    offset = 10.0 ** rng.uniform(-4.0, 0.0, size=(4 * count, 1))
    phi = rng.uniform(0.0, TWO_PI, size=(4 * count, 1))
    h = unit(n + offset * (np.cos(phi) * t + np.sin(phi) * b))
    v = random_unit(rng, 4 * count)
    v = unit(h + 0.9 * v)  # v·h > 0.1
    l = 2.0 * np.sum(v * h, axis=1, keepdims=True) * h - v
    keep = (np.sum(l * n, axis=1) > 1e-3) & (np.sum(v * n, axis=1) > 1e-3)
    index = np.flatnonzero(keep)[:count]
    assert len(index) == count
    return n[index], t_in[index], l[index], v[index]


def _grazing(dot: float, azimuth: float = 0.0) -> list[float]:
    """A unit vector at n·x = ``dot`` from n = +z, at ``azimuth`` in the tangent plane."""
    s = math.sqrt(1.0 - dot * dot)
    return [s * math.cos(azimuth), s * math.sin(azimuth), dot]


Z = [0.0, 0.0, 1.0]
X = [1.0, 0.0, 0.0]
TILTED = list(unit([1.0, 2.0, 3.0]))
TILTED_T = list(unit(np.cross(TILTED, [0.0, 0.0, 1.0])))
L0 = list(unit([0.55, 0.1, 0.8]))  # an ordinary light
V0 = list(unit([-0.5, 0.25, 0.8]))  # an ordinary view
NEAR_TILTED_L = list(unit(np.add(TILTED, [0.3, -0.2, 0.1])))
NEAR_TILTED_V = list(unit(np.add(TILTED, [-0.2, 0.25, 0.05])))


def _perp(a, scale):
    """``a`` plus a perpendicular of length ``scale``, not normalised."""
    p = unit(np.cross(a, [0.3, 0.5, 0.7]))
    return list(np.asarray(a) + scale * p)


# name -> (n, t, l, v). docs/design.md §8: grazing light and view, l = -v, h along n,
# tangents parallel to the normal (sphere poles), zero tangents, near-coincident l, v.
DEGENERATE: dict[str, tuple[list[float], list[float], list[float], list[float]]] = {
    # Grazing light: n·l exactly 0, tiny, and slightly below the horizon.
    "grazing-light:n.l=0": (Z, X, _grazing(0.0, 0.3), V0),
    "grazing-light:n.l=1e-7": (Z, X, _grazing(1e-7, 0.3), V0),
    "grazing-light:n.l=1e-4": (Z, X, _grazing(1e-4, 0.3), V0),
    "grazing-light:n.l=-1e-7": (Z, X, _grazing(-1e-7, 0.3), V0),
    "grazing-light:n.l=-1e-4": (Z, X, _grazing(-1e-4, 0.3), V0),
    # Grazing view.
    "grazing-view:n.v=0": (Z, X, L0, _grazing(0.0, 2.5)),
    "grazing-view:n.v=1e-7": (Z, X, L0, _grazing(1e-7, 2.5)),
    "grazing-view:n.v=1e-4": (Z, X, L0, _grazing(1e-4, 2.5)),
    "grazing-view:n.v=-1e-7": (Z, X, L0, _grazing(-1e-7, 2.5)),
    "grazing-view:n.v=-1e-4": (Z, X, L0, _grazing(-1e-4, 2.5)),
    # Both grazing; mirrored about n, so h is n exactly and only the clamps bound f.
    "grazing-both:n.l=n.v=0": (Z, X, _grazing(0.0, 0.0), _grazing(0.0, 1.0)),
    "grazing-both-mirror:n.l=n.v=0": (Z, X, _grazing(0.0, 0.4), _grazing(0.0, 0.4 + PI)),
    "grazing-both-mirror:n.l=n.v=1e-7": (Z, X, _grazing(1e-7, 0.4), _grazing(1e-7, 0.4 + PI)),
    "grazing-both-mirror:n.l=n.v=1e-4": (Z, X, _grazing(1e-4, 0.4), _grazing(1e-4, 0.4 + PI)),
    "grazing-both:n.l=n.v=-1e-7": (Z, X, _grazing(-1e-7, 0.4), _grazing(-1e-7, 2.0)),
    "grazing-light-view-above:n.l=1e-7,n.v=0.8": (Z, X, _grazing(1e-7, 0.0), _grazing(0.8, PI)),
    # l = -v: no half vector, no specular.
    "l=-v": (Z, X, L0, [-c for c in L0]),
    "l=-v:grazing": (Z, X, X, [-1.0, 0.0, 0.0]),
    "l=-v:tilted": (TILTED, TILTED_T, NEAR_TILTED_L, [-c for c in NEAR_TILTED_L]),
    "l~-v:|l+v|=1e-3": (Z, X, _grazing(0.0005, 0.7), _grazing(0.0005, 0.7 + PI)),
    "l~-v:|l+v|=1e-5": (Z, X, _grazing(0.000005, 0.7), _grazing(0.000005, 0.7 + PI)),
    # h exactly along n.
    "h=n:l=v=n": (Z, X, Z, Z),
    "h=n:mirror": (Z, X, _grazing(0.8, 0.9), _grazing(0.8, 0.9 + PI)),
    "h=n:mirror-steep": (Z, X, _grazing(0.05, 1.9), _grazing(0.05, 1.9 + PI)),
    "h=n:l=v=n-tilted": (TILTED, TILTED_T, TILTED, TILTED),
    "h=-n:l=v=-n": (Z, X, [0.0, 0.0, -1.0], [0.0, 0.0, -1.0]),
    "h-on-horizon": (Z, X, _grazing(0.6, 0.2), [*_grazing(0.6, 0.2)[:2], -0.6]),
    # Tangents parallel to the normal (sphere poles), zero, tiny.
    "t=n": (Z, Z, L0, V0),
    "t=-n": (Z, [0.0, 0.0, -1.0], L0, V0),
    "t=n:n=+x": (X, X, [0.8, 0.6, 0.0], [0.8, 0.0, 0.6]),
    "t=n:pole-n=+y": ([0.0, 1.0, 0.0], [0.0, 1.0, 0.0], [0.3, 0.9, 0.3], [-0.2, 0.95, 0.2]),
    "t=n:tilted": (TILTED, TILTED, NEAR_TILTED_L, NEAR_TILTED_V),
    "t~n:1e-2": (Z, _perp(Z, 1e-2), L0, V0),
    "t~n:1e-2-tilted": (TILTED, _perp(TILTED, 1e-2), NEAR_TILTED_L, NEAR_TILTED_V),
    "t=0": (Z, [0.0, 0.0, 0.0], L0, V0),
    "t=0:tilted": (TILTED, [0.0, 0.0, 0.0], NEAR_TILTED_L, NEAR_TILTED_V),
    "t=1e-7*x": (Z, [1e-7, 0.0, 0.0], L0, V0),
    "t=1e-5*x": (Z, [1e-5, 0.0, 0.0], L0, V0),
    # Near-coincident light and view.
    "l=v": (Z, X, L0, L0),
    "l=v:grazing": (Z, X, X, X),
    "l~v:1e-7": (Z, X, L0, list(unit(_perp(L0, 1e-7)))),
    "l~v:1e-4": (Z, X, L0, list(unit(_perp(L0, 1e-4)))),
    "l~v:1e-4-tilted": (TILTED, TILTED_T, NEAR_TILTED_L, list(unit(_perp(NEAR_TILTED_L, 1e-4)))),
}

# The zero normal is kept apart: it is not a surface, so what to expect has to
# be defined. Expected: exactly what the reference gives, nothing reflected
# (radiance 0: n·l = 0 and D(hz = 0) = 0), finite and non-negative in any case.
# (The surface shader replaces a zero interpolated normal by +y before it
# shades; the probe calls shading_frame directly, so this checks its own guard.)
ZERO_NORMAL: dict[str, tuple[list[float], list[float], list[float], list[float]]] = {
    "n=0": ([0.0, 0.0, 0.0], X, L0, V0),
    "n=0:l=v": ([0.0, 0.0, 0.0], X, L0, L0),
    "n=0,t=0": ([0.0, 0.0, 0.0], [0.0, 0.0, 0.0], L0, V0),
}


def stack(cases) -> tuple[np.ndarray, ...]:
    """(n, t, l, v) arrays from an iterable of single (n, t, l, v) cases."""
    rows = list(cases)
    return tuple(np.array([row[i] for row in rows], dtype=np.float64) for i in range(4))


def shading_batch(seed: int, count: int = 256):
    """Random, lobe-aimed and every DEGENERATE case, as float32-exact float64 arrays."""
    rng = np.random.default_rng(seed)
    parts = [random_cases(rng, count), lobe_cases(rng, count), stack(DEGENERATE.values())]
    return tuple(as_f32(np.concatenate([p[i] for p in parts])) for i in range(4))


# -- agreement measures ------------------------------------------------------------

def probe_error(gl: np.ndarray, expected: np.ndarray, scale: float | None = None) -> np.ndarray:
    """|gl - ref| / (PROBE_RTOL · (|ref| + PROBE_FLOOR · max|ref|)): <= 1 passes."""
    if scale is None:
        scale = float(np.abs(expected).max())
    bound = PROBE_RTOL * (np.abs(expected) + PROBE_FLOOR * scale)
    diff = np.abs(gl.astype(np.float64) - expected)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(diff == 0.0, 0.0, diff / bound)


def check_probe(gl: np.ndarray, expected: np.ndarray, labels=None, scale=None) -> None:
    """Finite, of luminance ≥ 0 (a channel goes below 0 outside sRGB) and within the fp32
    tolerance, naming the worst case."""
    from radiance_checks import luminance

    assert gl.shape == expected.shape
    bad = ~np.isfinite(gl).all(axis=-1)
    assert not bad.any(), f"non-finite output in cases {_names(np.flatnonzero(bad), labels)}"
    y = luminance(gl)
    negative = y < -1e-6 * (1.0 + np.abs(gl).max(axis=-1))
    assert not negative.any(), f"luminance below 0 in cases {_names(np.flatnonzero(negative), labels)}"
    err = probe_error(gl, expected, scale).max(axis=-1)
    worst = int(err.argmax())
    assert err[worst] <= 1.0, (
        f"{int((err > 1).sum())} of {len(err)} cases over tolerance; worst "
        f"{_names([worst], labels)}: gl {gl[worst]} ref {expected[worst]} "
        f"({err[worst]:.3g}× the tolerance)")


def _names(index, labels) -> str:
    index = list(index)
    shown = [labels[i] if labels is not None and i < len(labels) else f"#{i}" for i in index[:8]]
    return ", ".join(str(s) for s in shown) + (" ..." if len(index) > 8 else "")


def plot_bound(expected: np.ndarray) -> float:
    return max(PLOT_TOLERANCE * float(expected.max()), PLOT_FLOOR)


# -- fireflies ----------------------------------------------------------------------

def _neighbours(values: np.ndarray) -> np.ndarray:
    """(8, H, W): the 8 neighbours of every pixel, NaN outside the image."""
    padded = np.pad(values, 1, constant_values=np.nan)
    h, w = values.shape
    return np.stack([padded[1 + dy:1 + dy + h, 1 + dx:1 + dx + w]
                     for dy in (-1, 0, 1) for dx in (-1, 0, 1) if dy or dx])


def isolated_spikes(image: np.ndarray, ratio: float = SPIKE_RATIO, floor: float = 0.0) -> np.ndarray:
    """Boolean mask of firefly pixels in a linear RGB(A) image.

    A pixel is a firefly if it is not finite, or if its brightest channel
    exceeds ``ratio`` × the median of its 8 neighbours (plus ``floor``) while
    *none* of those neighbours reaches 1/``ratio`` of it. A genuine highlight
    spanning several pixels (a blob, or a one-pixel-wide streak of an
    anisotropic lobe) always has a bright neighbour; a lone spike has none.
    """
    rgb = np.asarray(image, dtype=np.float64)[..., :3]
    finite = np.isfinite(rgb).all(axis=-1)
    value = np.where(finite, rgb.max(axis=-1), np.inf)
    around = _neighbours(np.where(finite, value, np.nan))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # all-NaN neighbourhoods
        median = np.nanmedian(around, axis=0)
    median = np.where(np.isnan(median), 0.0, median)
    with np.errstate(invalid="ignore"):
        bright = (around >= value / ratio).sum(axis=0)
    spike = (value > ratio * median + floor) & (bright == 0)
    return ~finite | spike


def fireflies(image: np.ndarray) -> np.ndarray:
    """``isolated_spikes`` of a render, ignoring spikes under 1% of the object's
    median brightness (a faint lone pixel on a black object is no firefly)."""
    rgb = np.asarray(image, dtype=np.float64)
    covered = rgb[..., 3] > 0.5
    value = np.nan_to_num(rgb[..., :3].max(axis=-1), nan=0.0, posinf=0.0)
    typical = float(np.median(value[covered])) if covered.any() else 0.0
    return isolated_spikes(image, floor=0.01 * typical + 1e-12)
