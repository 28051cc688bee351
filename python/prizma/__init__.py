"""Prizma from Python: spectral EXR files as numpy arrays, relighting, colour, rendering.

Thin over the C++ libraries the tools use (docs/python.md): ``prizma.relight`` returns the pixels
``prizma-relight`` writes, ``prizma.read``/``prizma.write`` are the tools' reader and writer (checksum
included), ``prizma.render`` is ``prizma-render``'s renderer.

Errors are raised as :class:`InputError` (a ``ValueError``: bad input, the tools' exit status 2) or
:class:`RuntimeFailure` (a ``RuntimeError``: the tools' exit status 1), with the one-line message
the tools print after ``<program>: error:``.
"""

import json as _json
import os as _os

import numpy as _np

from . import _prizma
from ._prizma import InputError, RuntimeFailure
from ._serve import Server
from . import _serve

__all__ = [
    "Image", "InputError", "RuntimeFailure", "read", "write", "checksum", "relight", "spectrum", "xyz",
    "lab", "delta_e2000", "named_spectra", "render", "denoise", "metamer", "design_light", "version", "data_dir",
    "serve", "Server",
]

__version__ = _prizma.version()


def version():
    """The Prizma version string (with the git revision), as ``--version`` prints it."""
    return _prizma.version()


def data_dir():
    """The data folder in use (CIE tables, OCIO config): $PRIZMA_DATA_DIR if set, else the build's."""
    return _prizma.data_dir()


def _input_error(input, reason):
    """An InputError as the C++ side makes them: str() "input: reason", with .input and .reason."""
    e = InputError(f"{input}: {reason}")
    e.input, e.reason = input, reason
    return e


class Image:
    """A spectral image: per light, per pixel, per bin the transport under unit white light.

    Attributes:
        lights: dict, light name → float32 array of shape (height, width, bins), in the file's
            layer order. A single-layer file has one entry (its light's name, or "default").
        variance: dict, light name → float32 array of the same shape (variance of the mean), only
            for the lights that have one.
        bin_edges_nm: float64 array of the bins + 1 exact bin edges in nm.
        attributes: dict of the file's prizma: attributes: samples, sample_range, seed, scene_hash,
            version, wavelength_sampling, mis_lane_groups (spectral MIS's paths per sample, 0 when not
            recorded), scene_path, render_options, lights (the recorded lights,
            a list of dicts: name, direction, angularSizeDeg, spectrum), denoised (None for raw
            Monte Carlo means, else prizma:denoised as a dict: method, version, guides, variance,
            parameters; :func:`denoise`) and is_prizma.
        stats: for an image from :func:`render`, the render's statistics (paths, wall_seconds, …).
        reradiation: dict, light name → float32 array (height, width, pairs): the bispectral
            (fluorescence) terms M[out][in] of the pairs in ``reradiation_pairs``; empty for a file
            without fluorescence. Every light has the same pairs (docs/fluorescence.md).
        reradiation_pairs: int32 array (pairs, 2) of (in, out) bin indices, sorted, in ≠ out.
        guides: dict, guide name → float32 array (height, width): the light-independent guide
            layers of a render with --features (``depth``, ``scatter``; docs/spectral-exr.md), which
            :func:`denoise` uses; ``guide_variance`` the same for their variances of the mean.

    Arrays read from a file are numpy arrays over the reader's own buffers (no copy).
    """

    def __init__(self, lights, bin_edges_nm, variance=None, attributes=None, reradiation=None,
                 reradiation_pairs=None):
        """``reradiation``: the bispectral terms, either {light: (height, width, pairs)} with
        ``reradiation_pairs``, or without them {light: (height, width, bins, bins)} matrices M[out][in]
        (see :meth:`set_reradiation_matrices`)."""
        self.lights = dict(lights)
        self.bin_edges_nm = _np.asarray(bin_edges_nm, dtype=_np.float64)
        self.variance = dict(variance or {})
        self.attributes = dict(attributes or {})
        self.stats = None
        self.guides = {}
        self.guide_variance = {}
        self.reradiation = {}
        self.reradiation_pairs = _np.zeros((0, 2), dtype=_np.int32)
        if reradiation_pairs is not None:
            self.reradiation = dict(reradiation or {})
            self.reradiation_pairs = _np.asarray(reradiation_pairs, dtype=_np.int32).reshape(-1, 2)
        elif reradiation:
            self.set_reradiation_matrices(reradiation)

    def set_reradiation_matrices(self, matrices):
        """Sets the bispectral terms from one re-radiation matrix per light: {light: array of shape
        (height, width, bins, bins)}, M[y, x, out, in] the radiance in bin ``out`` per unit light in bin
        ``in`` (bin averages, as prizma-render writes them). The diagonal must be zero: it is the
        light's layer in ``lights``. The pairs kept are the off-diagonal entries that are non-zero in
        some pixel of some light (every light gets the same pairs, as the layout requires)."""
        n = self.bins
        mats = {}
        used = _np.zeros((n, n), dtype=bool)
        for name, m in matrices.items():
            m = _np.asarray(m, dtype=_np.float32)
            if m.ndim != 4 or m.shape[2:] != (n, n):
                raise _input_error(f'reradiation["{name}"]', f"must have shape (height, width, {n}, {n}), not {m.shape}")
            diag = _np.diagonal(m, axis1=2, axis2=3)
            if _np.any(diag != 0):
                raise _input_error(f'reradiation["{name}"]', "has a non-zero diagonal (that is the light's T layer)")
            used |= _np.any(m != 0, axis=(0, 1))
            mats[name] = m
        outs, ins = _np.nonzero(used)  # used[out, in]
        order = _np.lexsort((outs, ins))  # by (in, out)
        ins, outs = ins[order], outs[order]
        self.reradiation_pairs = _np.stack([ins, outs], axis=1).astype(_np.int32).reshape(-1, 2)
        self.reradiation = {name: _np.ascontiguousarray(m[:, :, outs, ins]) for name, m in mats.items()}

    def reradiation_matrix(self, light):
        """The light's re-radiation matrix, float32 (height, width, bins, bins), M[y, x, out, in]; zero
        outside the stored pairs and on the diagonal."""
        n = self.bins
        m = _np.zeros((self.height, self.width, n, n), dtype=_np.float32)
        if len(self.reradiation_pairs):
            ins, outs = self.reradiation_pairs[:, 0], self.reradiation_pairs[:, 1]
            m[:, :, outs, ins] = self.reradiation[light]
        return m

    @classmethod
    def _from_native(cls, d):
        attrs = dict(d["attributes"])
        text = attrs.pop("lights_json", "")
        try:
            attrs["lights"] = _json.loads(text) if text else []
        except ValueError:
            attrs["lights"] = text  # not JSON: kept as the file has it
        denoised = attrs.get("denoised", "")
        try:
            attrs["denoised"] = _json.loads(denoised) if denoised else None
        except ValueError:
            attrs["denoised"] = denoised  # not JSON: kept as the file has it
        image = cls(d["lights"], d["bin_edges_nm"], d["variance"], attrs, d.get("reradiation"),
                    d.get("reradiation_pairs"))
        image.stats = d.get("stats")
        image.guides = dict(d.get("guides") or {})
        image.guide_variance = dict(d.get("guide_variance") or {})
        return image

    def _native(self):
        attrs = dict(self.attributes)
        lights = attrs.pop("lights", None)
        attrs.pop("is_prizma", None)
        denoised = attrs.get("denoised")
        attrs["denoised"] = "" if denoised is None else denoised if isinstance(denoised, str) else _json.dumps(
            denoised, separators=(",", ":"))
        if isinstance(lights, str):
            attrs["lights_json"] = lights  # the writer refuses text its reader would refuse
        elif lights:
            try:  # strict JSON: NaN and infinities have no JSON form (Python would write NaN)
                attrs["lights_json"] = _json.dumps(lights, separators=(",", ":"), allow_nan=False)
            except (TypeError, ValueError) as e:
                raise _input_error('attributes["lights"]', f"cannot be stored as JSON ({e})") from None
        plane = lambda a: _np.asarray(a, dtype=_np.float32)[..., None]  # (height, width, 1), as a layer
        return {"bin_edges_nm": self.bin_edges_nm, "lights": self.lights, "variance": self.variance,
                "attributes": attrs, "reradiation": self.reradiation, "reradiation_pairs": self.reradiation_pairs,
                "guides": {k: plane(v) for k, v in self.guides.items()},
                "guide_variance": {k: plane(v) for k, v in self.guide_variance.items()}}

    @property
    def wavelengths_nm(self):
        """Bin centres in nm (what the channel names say), float64."""
        e = self.bin_edges_nm
        return 0.5 * (e[:-1] + e[1:])

    @property
    def bins(self):
        """Number of spectral bins."""
        return len(self.bin_edges_nm) - 1

    @property
    def height(self):
        return next(iter(self.lights.values())).shape[0] if self.lights else 0

    @property
    def width(self):
        return next(iter(self.lights.values())).shape[1] if self.lights else 0

    def png(self, lights=None, exposure=0.0, cmf="1931-2", display="sRGB", adapt=False, absolute=False, config=""):
        """The PNG ``prizma-relight FILE -o x.png`` writes for these settings (:func:`relight`'s), as
        bytes: the same writer (OpenColorIO display, ICC profile, prizma:* metadata), through a private
        temporary folder removed before it returns."""
        return _prizma.relight_png(self._native(), lights, float(exposure), str(cmf), str(display), bool(adapt),
                                   bool(absolute), _path(config, "config"))

    def _repr_png_(self):
        """Jupyter's (IPython's) rich display: the image under its default lights, :meth:`png`. None
        (no picture) for an image without lights."""
        return self.png() if self.lights else None

    def __repr__(self):
        e = self.bin_edges_nm
        span = f"{e[0]:g}–{e[-1]:g} nm" if len(e) else "no bins"
        return (f"<prizma.Image {self.width}×{self.height}, {self.bins} bins {span}, "
                f"lights {list(self.lights)}>")


def _path(p, name="path"):
    """A path argument (str, bytes or os.PathLike) as text; a NUL in it is refused as Python's
    open() refuses it (an InputError, a ValueError), not cut short by the C++ side."""
    p = _os.fsdecode(_os.fspath(p))
    if "\0" in p:
        raise _input_error(name, "embedded null byte")
    return p


def read(path, verify=True):
    """Reads a spectral EXR (a Prizma file or any reflective spectral EXR) into an :class:`Image`.

    The pixel checksum (prizma:checksum) is verified as prizma-relight verifies it, unless
    ``verify=False`` (prizma-relight --no-verify): a file another tool re-encoded (half, PXR24, B44)
    keeps the attribute but not the exact values. Raises InputError naming the path for files that
    are not spectral EXR, truncated or damaged.
    """
    return Image._from_native(_prizma.read(_path(path), bool(verify)))


def write(path, image, half=False):
    """Writes an :class:`Image` as a Prizma spectral EXR, atomically (a failure leaves no partial
    file and never destroys an existing one), with the pixel checksum. ``half=True`` writes half
    floats (values beyond 65504 are refused). The layout is the one prizma-render writes."""
    _prizma.write(_path(path), image._native(), bool(half))


def checksum(image):
    """The prizma:checksum string of an image in memory (equal to the stored one of the file it was
    read from)."""
    return _prizma.checksum(image._native())


def relight(image, lights=None, exposure=0.0, cmf="1931-2", display="sRGB", colour_space=None,
            adapt=False, absolute=False, config=""):
    """Relights a spectral image; returns a float32 array of shape (height, width, 3).

    Args:
        image: an :class:`Image` or the path of a spectral EXR.
        lights: None for each light's default (the spectrum recorded in the file, else D65); one
            light for every layer; or a dict {light name: light, or None for off}: lights not named
            keep their default. A light is a spec string ("D65", "A*0.5", "blackbody:3200K", "off",
            …), a pair (wavelengths_nm, values) of 1-D arrays (a measured SPD, normalised like any
            light), or {"spectrum": spec or pair, "scale": s}. One light for every layer given
            without a scale ("F11", a pair) keeps each light's recorded scale (a sky recorded as
            "D65*0.2" gets F11*0.2; a light recorded off stays off), as ``prizma-relight --light
            F11`` does; "F11*1" puts every light at scale 1.
        exposure: stops (EV), within ±64.
        cmf: colour matching functions: "1931-2", "1964-10", "2012-2", "2012-10".
        display: an OCIO display ("sRGB", "Display P3", "Rec.2020"): display-encoded values clamped
            to [0, 1], as prizma-relight writes a PNG or TIFF before quantising. None: linear XYZ,
            as an EXR output without --colour-space.
        colour_space: a linear colour space of the OCIO config ("Linear sRGB", "ACEScg"): the values
            prizma-relight writes to an EXR with --colour-space (display is then ignored).
        adapt: Bradford adaptation from the light mix's white to D65 (--adapt).
        absolute: absolute light units (--absolute).
        config: an OCIO config file; empty for $OCIO or Prizma's own.

    The same code as prizma-relight computes it (RelightSession): for the same settings the array
    equals the tool's output file. The GIL is released while relighting.
    """
    source = image._native() if isinstance(image, Image) else _path(image, "image")
    if colour_space is not None:
        display = display or "sRGB"
    return _prizma.relight(source, lights, float(exposure), str(cmf), display, colour_space, bool(adapt),
                           bool(absolute), _path(config, "config"))


def spectrum(spec, wavelengths_nm=None):
    """A spectrum from any spec string ("F11", "cc:dark-skin", "gaussian:550:20", "csv:file.csv",
    "D65*0.5", …) or pair (wavelengths_nm, values) → (wavelengths_nm, values), two float64 arrays: at
    the spectrum's own table, or at ``wavelengths_nm`` when given (piecewise linear, 0 outside the
    table). A constant is given at 360…830 nm every 1 nm.
    """
    at = None if wavelengths_nm is None else _np.ascontiguousarray(wavelengths_nm, dtype=_np.float64).ravel()
    return _prizma.spectrum(spec, at)


def xyz(spectrum, illuminant=None, cmf="1931-2"):
    """CIE XYZ (float64 array of 3) of a spectrum: a spec string or a pair (wavelengths_nm, values).

    Without ``illuminant``: the integral of spectrum × CMF over the CMF table (no normalisation).
    With an illuminant (spec or pair), ``spectrum`` is a reflectance: ∫R·E·cmf dλ / ∫E·ȳ dλ, so a
    perfect white has Y = 1 (the product tabulated every 1 nm).
    """
    return _prizma.xyz(spectrum, illuminant, str(cmf))


def lab(xyz, white=None):
    """CIELAB of XYZ values (array whose last axis has 3 values), relative to ``white`` (XYZ; default
    D65 with Y = 1)."""
    w = None if white is None else _np.ascontiguousarray(white, dtype=_np.float64).ravel()
    return _prizma.lab(_np.ascontiguousarray(xyz, dtype=_np.float64), w)


def delta_e2000(lab1, lab2):
    """CIEDE2000 colour difference (kL = kC = kH = 1) of CIELAB colours: a float for two colours, an
    array of shape (…) for arrays of shape (…, 3) (either may be a single colour)."""
    return _prizma.delta_e2000(_np.ascontiguousarray(lab1, dtype=_np.float64),
                               _np.ascontiguousarray(lab2, dtype=_np.float64))


def named_spectra():
    """The names spectrum specs accept: named illuminants (D65, A, F11, LED-B1, …) and ColorChecker
    patches (cc:dark-skin, …)."""
    return _prizma.named_spectra()


def render(scene, samples=None, threads=0, seed=None, width=None, height=None, bins=None, variance=False,
           progress=None, samples_per_pass=0, base_dir=None):
    """Renders a scene with prizma-render's path tracer; returns an :class:`Image`.

    Args:
        scene: a scene file (docs/scene-format.md) or a dict with its content (relative paths in
            it resolve against ``base_dir``, default the current folder).
        samples: samples per pixel (--spp); None for the scene's.
        threads: worker threads, 0 for all cores. The result does not depend on it.
        seed, width, height, bins, variance: as --seed, --width, --height, --bins, --variance.
        progress: called after every pass with a dict (samples_done, samples_total, paths,
            elapsed_seconds), on the calling thread. An exception it raises stops the render.
        samples_per_pass: samples per pixel per pass (0: automatic).

    Ctrl-C (SIGINT) stops the render at once: KeyboardInterrupt is raised, with the passes completed
    so far as its ``image`` attribute (a valid render of fewer samples) when there were any. The
    GIL is released while rendering. A scene given as a dict is read from memory (no file is
    written); errors name it ``scene``. Integer arguments are checked as the tools check their
    options (``seed=-1``: ``InputError: seed: …``).
    """
    if isinstance(scene, dict):
        folder = _path(base_dir, "base_dir") if base_dir is not None else _os.getcwd()
        return _render(_json.dumps(scene), True, folder, samples, threads, seed, width, height, bins, variance,
                       progress, samples_per_pass)
    return _render(_path(scene, "scene"), False, "", samples, threads, seed, width, height, bins, variance,
                   progress, samples_per_pass)


def _render(scene, scene_is_json, base_dir, samples, threads, seed, width, height, bins, variance, progress,
            samples_per_pass):
    try:
        native = _prizma.render(scene, scene_is_json, base_dir, samples, threads, seed, width, height, bins,
                                bool(variance), samples_per_pass, progress)
    except KeyboardInterrupt as e:
        partial = getattr(e, "_prizma_image", None)
        e.image = Image._from_native(partial) if partial is not None else None
        raise
    return Image._from_native(native)


def denoise(image, variance="propagate", window=5, patch=3, strength=0.45, centre_threshold=3.0, threads=0,
            guides="luminance"):
    """The image denoised as ``prizma-render denoise`` denoises a file (docs/denoise.md); a new
    :class:`Image`.

    One kernel per pixel, computed from light-independent guides (the white-light luminance of all
    lights and its variance), filters every bin of every light and every bispectral term, so
    relighting the result under any spectra equals filtering the relit raw image with the same
    kernels. The image needs variance layers (``render(..., variance=True)``, ``--variance``).

    Args:
        variance: "propagate" (the result's variance is Σ W²·Var, the filtered values' own noise with
            the weights held fixed) or "drop" (no variance layers).
        window, patch: kernel and patch radii in pixels (1–15, 0–7).
        strength: k of the patch distance (> 0); larger averages more and blurs more.
        centre_threshold: standard errors past which a neighbour is cut off (0: no such test).
        threads: worker threads, 0 for all cores. The result does not depend on it.
        guides: "luminance" (default), or "features": the image's guide layers (``image.guides``,
            a render with --features) as well (prizma-render denoise --guides features).

    The result's ``attributes["denoised"]`` records the method, parameters and guides, as the file
    ``write`` makes of it does (prizma:denoised). Raises InputError for an image without variance,
    one already denoised, or options out of range. The GIL is released while it runs.
    """
    return Image._from_native(_prizma.denoise(image._native(), str(variance), str(guides), window, patch,
                                              float(strength), float(centre_threshold), threads))


def metamer(albedo, match_light="D65", split_light="A", cmf="1931-2", bins=None, basis_size=20,
            min_split_delta_e=0.5):
    """Designs a smooth reflectance in [0, 1] with the colour of ``albedo`` under ``match_light`` and
    as different as possible under ``split_light`` (prizma-metamer metamer). Spectra are spec
    strings or (wavelengths_nm, values) pairs; ``bins`` a bin spec ("linear:400:700:12", default
    1 nm over 380–780 nm). Returns a dict: reflectance (wavelengths_nm, values), delta_e_match,
    delta_e_split."""
    return _prizma.metamer(albedo, match_light, split_light, str(cmf), bins, int(basis_size),
                           float(min_split_delta_e))


def design_light(albedo_a, albedo_b, goal="reveal", reference="D65", primaries=(), cmf="1931-2", bins=None,
                 max_power_ratio=2.0):
    """Designs a light under which two albedos look the same (goal "hide") or as different as
    possible (goal "reveal"), at the luminance of ``reference``, free-form or as a non-negative mix
    of ``primaries`` (prizma-metamer light). Returns a dict: light (wavelengths_nm, values), weights,
    delta_e (under the light), delta_e_reference."""
    return _prizma.design_light(albedo_a, albedo_b, str(goal), reference, list(primaries), str(cmf), bins,
                                float(max_power_ratio))


def serve(image, port=0, bind="127.0.0.1", save_dir=None, lights=None, exposure=0.0, display="sRGB"):
    """Opens the live relighting page for an image: runs ``prizma-relight FILE --serve`` (the tool
    installed with this module) and prints the page's URL with its secret token, as the tool does.

    Args:
        image: an :class:`Image` (written to ``image.exr`` in a private temporary folder, mode 0600,
            removed when the server stops) or the path of a spectral EXR.
        port: 0 for a free port; bind: the address to listen on (--bind).
        save_dir: where the page's Save writes (--save-dir); default the current folder.
        lights, exposure, display: the page's starting state (--light, --exposure, --display);
            lights as spec strings: one for every layer, or {name: spec or None for off}.

    Returns a :class:`Server`: ``url``, ``port``, ``stop()``; a context manager. Errors are the tool's
    (InputError for a bad file, option or a port in use). The server stops at ``stop()``, at the end
    of a ``with`` block, when the object is collected, or when the interpreter exits.
    """
    return _serve.serve(image, _path, write, port=port, bind=bind, save_dir=save_dir, lights=lights,
                        exposure=exposure, display=display)
