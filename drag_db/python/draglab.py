"""draglab: Python bindings (ctypes) of the libdraglab C ABI (draglab/draglab.h).

    import draglab
    with draglab.Database("draglab.db") as db:
        law = db.load("bvk2007@1")
        law.F(0.3, 50.0)                    # canonical drag-only F(phi, Re)
        law.F_array([0.1, 0.4], [0.0, 100.0])
        law.beta(eps_g=0.6, mu_g=1.8e-5, rho_g=1.2, slip=0.5, d_p=5e-4, rho_s=2500.0)

Conventions: phi solids fraction, eps = 1 - phi; Re = rho eps d u / mu with u the interstitial
slip; F = F_d / (3 pi mu d eps u), drag only; beta = 18 mu phi eps F / d^2 [kg m^-3 s^-1];
K = F / (1 - phi) includes the mean pressure gradient.

Every failing call raises DraglabError(code, message) with the status code of draglab.h. An
argument of the wrong type raises DraglabTypeError and one of the wrong shape DraglabValueError:
both are DraglabError (code INVALID_ARGUMENT) and also the built-in TypeError / ValueError, and
both name the argument. Numbers must be real: complex values, strings, None and bools are refused,
never converted. F_array broadcasts numpy inputs like numpy and returns the broadcast shape.
No compiler is needed: only the shared library. It is found from the environment variable
DRAGLAB_LIBRARY (a path to libdraglab), else next to this file, else in the libdir of the
installed draglab's pkg-config file (`pkg-config --variable=libdir draglab`, so
PKG_CONFIG_PATH finds an installation under any prefix), else by
ctypes.util.find_library("draglab"). Installable with `pip install ./drag_db/python`.
"""

import ctypes
import ctypes.util
import glob
import numbers
import os
import re as _re
import subprocess
import sys
from array import array

__all__ = [
    "DraglabError", "DraglabTypeError", "DraglabValueError", "Database", "Law", "version", "library_path",
    "OK", "INVALID_ARGUMENT", "OUT_OF_VALIDITY", "NOT_FOUND", "IMMUTABLE", "DATABASE_ERROR",
    "SCHEMA_TOO_NEW", "NOT_A_DATABASE", "INTERNAL",
    "RANGE_ERROR", "RANGE_CLAMP", "RANGE_EXTRAPOLATE",
]

# Status codes (draglab.h).
OK = 0
INVALID_ARGUMENT = 1
OUT_OF_VALIDITY = 2
NOT_FOUND = 3
IMMUTABLE = 4
DATABASE_ERROR = 5
SCHEMA_TOO_NEW = 6
NOT_A_DATABASE = 7
INTERNAL = 8
IO_ERROR = 9

# Range policies for inputs outside a law's validity box.
RANGE_ERROR = 0
RANGE_CLAMP = 1
RANGE_EXTRAPOLATE = 2
_POLICY_NAMES = {"error": RANGE_ERROR, "clamp": RANGE_CLAMP, "extrapolate": RANGE_EXTRAPOLATE}


class DraglabError(Exception):
    """A non-zero status from libdraglab: .code (draglab.h status) and .message."""

    def __init__(self, code, message):
        super().__init__("draglab error %d: %s" % (code, message))
        self.code = code
        self.message = message


class DraglabTypeError(DraglabError, TypeError):
    """An argument of the wrong type (named in the message); code INVALID_ARGUMENT."""

    def __init__(self, message):
        super().__init__(INVALID_ARGUMENT, message)


class DraglabValueError(DraglabError, ValueError):
    """Arguments of incompatible shapes or lengths (named in the message); code
    INVALID_ARGUMENT."""

    def __init__(self, message):
        super().__init__(INVALID_ARGUMENT, message)


def _describe(value):
    """How a refused argument is shown: its type and a short repr."""
    text = repr(value)
    if len(text) > 40:
        text = text[:37] + "..."
    return "%s %s" % (type(value).__name__, text) if value is not None else "None"


def _real(value, name):
    """A real scalar argument as float; anything else raises DraglabTypeError naming `name`."""
    if _np is not None and isinstance(value, _np.ndarray) and value.ndim == 0 \
            and value.dtype.kind in "fiu":
        return float(value)
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        if isinstance(value, numbers.Complex):
            raise DraglabTypeError("%s must be a real number, got the complex %r (the imaginary "
                                   "part is not dropped silently)" % (name, value))
        raise DraglabTypeError("%s must be a real number, got %s" % (name, _describe(value)))
    return float(value)


def _text_argument(value, name, example):
    if not isinstance(value, str):
        raise DraglabTypeError("%s must be a str such as %s, got %s"
                               % (name, example, _describe(value)))
    return value


# ---- locating and loading the library --------------------------------------------------------

def _candidate_paths():
    env = os.environ.get("DRAGLAB_LIBRARY")
    if env:
        yield env
        return
    patterns = ("libdraglab.so", "libdraglab.so.*", "libdraglab.dylib", "libdraglab*.dylib",
                "draglab.dll", "libdraglab.dll")
    here = os.path.dirname(os.path.abspath(__file__))
    for pattern in patterns:
        for path in sorted(glob.glob(os.path.join(here, pattern))):
            yield path
    try:
        libdir = subprocess.run(["pkg-config", "--variable=libdir", "draglab"],
                                capture_output=True, text=True, timeout=10).stdout.strip()
    except (OSError, subprocess.SubprocessError):
        libdir = ""
    if libdir:
        for pattern in patterns:
            for path in sorted(glob.glob(os.path.join(libdir, pattern))):
                yield path
    found = ctypes.util.find_library("draglab")
    if found:
        yield found


def _load_library():
    tried = []
    for path in _candidate_paths():
        try:
            return ctypes.CDLL(path), path
        except OSError as error:
            tried.append("%s (%s)" % (path, error))
    raise ImportError(
        "draglab: cannot load libdraglab; set DRAGLAB_LIBRARY to its path, or put draglab.py "
        "next to it" + ("; tried: " + "; ".join(tried) if tried else ""))


_lib, library_path = _load_library()

_c_double_p = ctypes.POINTER(ctypes.c_double)
_db_p = ctypes.c_void_p
_law_p = ctypes.c_void_p


def _declare(name, restype, *argtypes):
    function = getattr(_lib, name)
    function.restype = restype
    function.argtypes = list(argtypes)
    return function


_version = _declare("draglab_version", ctypes.c_char_p)
_last_error = _declare("draglab_last_error", ctypes.c_char_p)
_db_open = _declare("draglab_db_open", ctypes.c_int, ctypes.c_char_p, ctypes.POINTER(_db_p))
_db_open_readonly = _declare("draglab_db_open_readonly", ctypes.c_int, ctypes.c_char_p,
                             ctypes.POINTER(_db_p))
_db_close = _declare("draglab_db_close", None, _db_p)
_law_load = _declare("draglab_law_load", ctypes.c_int, _db_p, ctypes.c_char_p,
                     ctypes.POINTER(_law_p))
_law_free = _declare("draglab_law_free", None, _law_p)
_law_name = _declare("draglab_law_name", ctypes.c_char_p, _law_p)
_law_version = _declare("draglab_law_version", ctypes.c_int, _law_p)
_law_form = _declare("draglab_law_form", ctypes.c_char_p, _law_p)
_law_hash = _declare("draglab_law_hash", ctypes.c_char_p, _law_p)
_law_num_extra = _declare("draglab_law_num_extra", ctypes.c_int, _law_p)
_law_validity = _declare("draglab_law_validity", ctypes.c_int, _law_p, _c_double_p, _c_double_p,
                         _c_double_p, _c_double_p)
_law_set_range_policy = _declare("draglab_law_set_range_policy", ctypes.c_int, _law_p,
                                 ctypes.c_int)
_law_range_policy = _declare("draglab_law_range_policy", ctypes.c_int, _law_p,
                             ctypes.POINTER(ctypes.c_int))
_law_out_of_range_count = _declare("draglab_law_out_of_range_count", ctypes.c_int, _law_p,
                                   ctypes.POINTER(ctypes.c_longlong))
_law_F = _declare("draglab_law_F", ctypes.c_int, _law_p, ctypes.c_double, ctypes.c_double,
                  _c_double_p)
_law_F_extra = _declare("draglab_law_F_extra", ctypes.c_int, _law_p, ctypes.c_double,
                        ctypes.c_double, _c_double_p, _c_double_p)
_law_F_n = _declare("draglab_law_F_n", ctypes.c_int, _law_p, ctypes.c_size_t, _c_double_p,
                    _c_double_p, _c_double_p)
_law_beta_d2_over_mu = _declare("draglab_law_beta_d2_over_mu", ctypes.c_int, _law_p,
                                ctypes.c_double, ctypes.c_double, _c_double_p)
_law_K = _declare("draglab_law_K", ctypes.c_int, _law_p, ctypes.c_double, ctypes.c_double,
                  _c_double_p)
_law_beta = _declare("draglab_law_beta", ctypes.c_int, _law_p, *([ctypes.c_double] * 6),
                     _c_double_p)
_law_dga = _declare("draglab_law_dga", ctypes.c_int, _law_p, *([ctypes.c_double] * 6),
                    _c_double_p)
_law_export = _declare("draglab_law_export", ctypes.c_int, _law_p, ctypes.c_char_p,
                       ctypes.c_char_p, ctypes.c_size_t, ctypes.POINTER(ctypes.c_size_t))


def _message():
    text = _last_error()
    return text.decode("utf-8", "replace") if text else ""


def _check(status):
    if status != OK:
        raise DraglabError(status, _message())


def _text(raw):
    return raw.decode("utf-8", "replace") if raw else ""


def version():
    """Library version, e.g. "0.1.0 (g1234abc)"."""
    return _text(_version())


# ---- arrays ----------------------------------------------------------------------------------

try:  # numpy is optional: used only if it is installed
    import numpy as _np
except ImportError:  # pragma: no cover - depends on the interpreter
    _np = None


def _real_ndarray(values, name):
    """A numpy array of float64 from array-like `values` of real numbers (any shape)."""
    data = _np.asarray(values)
    if data.dtype.kind == "c":
        raise DraglabTypeError("%s must be real, got a complex array (the imaginary part is not "
                               "dropped silently)" % name)
    if data.dtype.kind not in "fiu":
        raise DraglabTypeError("%s must be an array of real numbers, got dtype %s"
                               % (name, data.dtype))
    return data.astype(_np.float64, copy=False)


def _as_double_buffer(values, name):
    """(ctypes pointer, keep-alive object, length) for a flat sequence of reals, without copying
    numpy float64 arrays or array('d') objects."""
    if _np is not None and isinstance(values, _np.ndarray):
        contiguous = _np.ascontiguousarray(_real_ndarray(values, name)).reshape(-1)
        return contiguous.ctypes.data_as(_c_double_p), contiguous, contiguous.size
    if isinstance(values, array) and values.typecode == "d":
        address, length = values.buffer_info()
        return ctypes.cast(address, _c_double_p), values, length
    if isinstance(values, (str, bytes)):
        raise DraglabTypeError("%s must be a sequence of real numbers, got %s"
                               % (name, _describe(values)))
    try:
        data = array("d", values)
    except TypeError:
        raise DraglabTypeError("%s must be a flat sequence of real numbers (a numpy array for "
                               "more dimensions), got %s" % (name, _describe(values))) from None
    address, length = data.buffer_info()
    return ctypes.cast(address, _c_double_p), data, length


# ---- database and laws -----------------------------------------------------------------------

class Database:
    """An open draglab database (SQLite file); a context manager. Not thread-safe: one per thread.

    Database(path=None) opens, creating and seeding the literature library if missing;
    path None or "" -> $DRAGLAB_DB, else ./draglab.db.
    Database(path, read_only=True) opens an existing file read-only (draglab_db_open_readonly):
    nothing is written, created, migrated or seeded, and a file and directory without write
    permission can be read (in a directory without write permission the file is read as
    immutable: changes made while it is open are not seen). A missing file raises NOT_FOUND.
    """

    def __init__(self, path=None, read_only=False):
        self._handle = None
        handle = _db_p()
        if path is not None and not isinstance(path, (str, bytes, os.PathLike)):
            raise DraglabTypeError("path must be a str, bytes or os.PathLike (or None for the "
                                   "default database), got %s" % _describe(path))
        encoded = None if path is None else os.fsencode(path)
        opener = _db_open_readonly if read_only else _db_open
        _check(opener(encoded, ctypes.byref(handle)))
        self._handle = handle

    def load(self, reference, range_policy=None):
        """Loads "name", "name@3", "name@latest" or "name@<hash prefix>" as a Law. The law does
        not need the database afterwards. range_policy: "error" (default), "clamp" or
        "extrapolate". A retracted version loads with .warning set."""
        self._require_open()
        _text_argument(reference, "reference", "'bvk2007@1'")
        handle = _law_p()
        _check(_law_load(self._handle, reference.encode("utf-8"), ctypes.byref(handle)))
        law = Law(handle, warning=_message())
        if range_policy is not None:
            law.range_policy = range_policy
        return law

    def close(self):
        if getattr(self, "_handle", None):
            _db_close(self._handle)
            self._handle = None

    def _require_open(self):
        if not self._handle:
            raise DraglabError(INVALID_ARGUMENT, "the database is closed")

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
        return False

    def __del__(self):
        self.close()


class Law:
    """A loaded, immutable law version. Thread-safe evaluation (set the range policy first)."""

    def __init__(self, handle, warning=""):
        self._handle = handle
        # A successful draglab_law_load leaves "" or the warning of a retracted or draft version.
        self.warning = warning

    # -- identity --
    @property
    def name(self):
        return _text(_law_name(self._live()))

    @property
    def version(self):
        return _law_version(self._live())

    @property
    def reference(self):
        return "%s@%d" % (self.name, self.version)

    @property
    def form(self):
        return _text(_law_form(self._live()))

    @property
    def hash(self):
        """Content hash (64 hex digits)."""
        return _text(_law_hash(self._live()))

    @property
    def num_extra(self):
        """Number of extra inputs (polydisperse forms: 1, the size ratio y = d_i/<d>)."""
        return _law_num_extra(self._live())

    @property
    def validity(self):
        """((phi_min, phi_max), (re_min, re_max))."""
        values = [ctypes.c_double() for _ in range(4)]
        _check(_law_validity(self._live(), *[ctypes.byref(v) for v in values]))
        return (values[0].value, values[1].value), (values[2].value, values[3].value)

    # -- range policy --
    @property
    def range_policy(self):
        """"error" (default), "clamp" or "extrapolate"."""
        policy = ctypes.c_int()
        _check(_law_range_policy(self._live(), ctypes.byref(policy)))
        return {v: k for k, v in _POLICY_NAMES.items()}[policy.value]

    @range_policy.setter
    def range_policy(self, policy):
        if isinstance(policy, str):
            if policy not in _POLICY_NAMES:
                raise DraglabError(INVALID_ARGUMENT, "range policy '%s' is not one of: %s"
                                   % (policy, ", ".join(_POLICY_NAMES)))
            policy = _POLICY_NAMES[policy]
        elif isinstance(policy, bool) or not isinstance(policy, numbers.Integral):
            raise DraglabTypeError("range_policy must be one of %s (or RANGE_ERROR, RANGE_CLAMP, "
                                   "RANGE_EXTRAPOLATE), got %s"
                                   % (", ".join(_POLICY_NAMES), _describe(policy)))
        _check(_law_set_range_policy(self._live(), int(policy)))

    @property
    def out_of_range_count(self):
        """Number of clamped or extrapolated evaluations since load."""
        count = ctypes.c_longlong()
        _check(_law_out_of_range_count(self._live(), ctypes.byref(count)))
        return count.value

    # -- evaluation --
    def F(self, phi, re, extra=None):
        """Canonical drag-only F(phi, Re), dimensionless."""
        out = ctypes.c_double()
        phi, re = _real(phi, "phi"), _real(re, "re")
        if extra is None:
            _check(_law_F(self._live(), phi, re, ctypes.byref(out)))
        else:
            if isinstance(extra, numbers.Number):
                extra = [_real(extra, "extra")]
            pointer, keep, length = _as_double_buffer(extra, "extra")
            if length < self.num_extra:
                raise DraglabError(INVALID_ARGUMENT, "%s needs %d extra input(s), got %d"
                                   % (self.reference, self.num_extra, length))
            _check(_law_F_extra(self._live(), phi, re, pointer, ctypes.byref(out)))
            del keep
        return out.value

    def F_array(self, phi, re):
        """F over arrays in one call. numpy input (either argument): broadcast like numpy, a
        numpy array of the broadcast shape returned. Otherwise flat sequences of equal length
        (or one of them a scalar), an array('d') returned. On a bad value raises DraglabError
        naming the first bad index (and its place in the broadcast shape)."""
        if _np is not None and (isinstance(phi, _np.ndarray) or isinstance(re, _np.ndarray)):
            return self._F_ndarray(phi, re)
        if isinstance(phi, numbers.Number) and not isinstance(re, numbers.Number):
            phi = [_real(phi, "phi")] * len(self._sized(re, "re"))
        elif isinstance(re, numbers.Number) and not isinstance(phi, numbers.Number):
            re = [_real(re, "re")] * len(self._sized(phi, "phi"))
        phi_pointer, phi_keep, n = _as_double_buffer(phi, "phi")
        re_pointer, re_keep, n_re = _as_double_buffer(re, "re")
        if n != n_re:
            raise DraglabValueError("phi and re have different lengths (%d, %d)" % (n, n_re))
        out = array("d", bytes(8 * n))
        out_pointer = ctypes.cast(out.buffer_info()[0], _c_double_p) if n else None
        _check(_law_F_n(self._live(), n, phi_pointer if n else None, re_pointer if n else None,
                        out_pointer))
        del phi_keep, re_keep
        return out

    @staticmethod
    def _sized(values, name):
        try:
            len(values)
        except TypeError:
            raise DraglabTypeError("%s must be a real number or a sequence of them, got %s"
                                   % (name, _describe(values))) from None
        return values

    def _F_ndarray(self, phi, re):
        phi_array, re_array = _real_ndarray(phi, "phi"), _real_ndarray(re, "re")
        try:
            phi_b, re_b = _np.broadcast_arrays(phi_array, re_array)
        except ValueError:
            raise DraglabValueError("phi of shape %s and re of shape %s do not broadcast together "
                                    "(numpy's rules)" % (phi_array.shape, re_array.shape)) from None
        shape = phi_b.shape
        phi_flat = _np.ascontiguousarray(phi_b).reshape(-1)
        re_flat = _np.ascontiguousarray(re_b).reshape(-1)
        out = _np.empty(shape, dtype=_np.float64)
        n = phi_flat.size
        status = _law_F_n(self._live(), n, phi_flat.ctypes.data_as(_c_double_p) if n else None,
                          re_flat.ctypes.data_as(_c_double_p) if n else None,
                          out.ctypes.data_as(_c_double_p) if n else None)
        if status != OK:
            message = _message()
            found = _re.search(r"index (\d+)", message)
            if found and len(shape) > 1:
                place = tuple(int(i) for i in _np.unravel_index(int(found.group(1)), shape))
                message += " (element %s of the broadcast shape %s)" % (place, shape)
            raise DraglabError(status, message)
        return out

    def K(self, phi, re):
        """K = F / (1 - phi): total force including the mean pressure gradient part."""
        out = ctypes.c_double()
        phi, re = _real(phi, "phi"), _real(re, "re")
        _check(_law_K(self._live(), phi, re, ctypes.byref(out)))
        return out.value

    def beta_d2_over_mu(self, phi, re):
        """beta d^2 / mu = 18 phi (1 - phi) F."""
        out = ctypes.c_double()
        phi, re = _real(phi, "phi"), _real(re, "re")
        _check(_law_beta_d2_over_mu(self._live(), phi, re, ctypes.byref(out)))
        return out.value

    def beta(self, eps_g, mu_g, rho_g, slip, d_p, rho_s=1.0):
        """Friction coefficient beta [kg m^-3 s^-1] (argument order of MFiX's DRAG_USR): gas
        fraction, gas viscosity [Pa s], gas density [kg/m^3], interstitial slip [m/s], particle
        diameter [m], particle density [kg/m^3] (must be > 0; unused)."""
        out = ctypes.c_double()
        eps_g, mu_g, rho_g, slip, d_p, rho_s = (
            _real(v, n) for v, n in ((eps_g, "eps_g"), (mu_g, "mu_g"), (rho_g, "rho_g"),
                                     (slip, "slip"), (d_p, "d_p"), (rho_s, "rho_s")))
        _check(_law_beta(self._live(), eps_g, mu_g, rho_g, slip, d_p, rho_s, ctypes.byref(out)))
        return out.value

    def dga(self, eps_g, mu_g, rho_g, slip, d_p, rho_s=1.0):
        """MFiX's lDgA = beta / phi = 18 mu_g eps_g F / d_p^2 [kg m^-3 s^-1]."""
        out = ctypes.c_double()
        eps_g, mu_g, rho_g, slip, d_p, rho_s = (
            _real(v, n) for v, n in ((eps_g, "eps_g"), (mu_g, "mu_g"), (rho_g, "rho_g"),
                                     (slip, "slip"), (d_p, "d_p"), (rho_s, "rho_s")))
        _check(_law_dga(self._live(), eps_g, mu_g, rho_g, slip, d_p, rho_s, ctypes.byref(out)))
        return out.value

    def export(self, format="c"):
        """Standalone source of this law version: format "c", "fortran" or "json"."""
        length = ctypes.c_size_t()
        encoded = _text_argument(format, "format", "'c', 'fortran' or 'json'").encode("utf-8")
        _check(_law_export(self._live(), encoded, None, 0, ctypes.byref(length)))
        buffer = ctypes.create_string_buffer(length.value + 1)
        _check(_law_export(self._live(), encoded, buffer, length.value + 1, ctypes.byref(length)))
        return buffer.value.decode("utf-8")

    # -- lifetime --
    def close(self):
        if getattr(self, "_handle", None):
            _law_free(self._handle)
            self._handle = None

    def _live(self):
        if not self._handle:
            raise DraglabError(INVALID_ARGUMENT, "the law has been closed")
        return self._handle

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
        return False

    def __del__(self):
        self.close()

    def __repr__(self):
        if not self._handle:
            return "<draglab.Law (closed)>"
        return "<draglab.Law %s form=%s hash=%s>" % (self.reference, self.form, self.hash[:12])


if __name__ == "__main__":  # pragma: no cover - a quick manual check
    print("draglab %s (%s)" % (version(), library_path), file=sys.stderr)
