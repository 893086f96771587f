"""The draglab Python module (ctypes over the C ABI) as a Python user sees it.

Set-up: a fresh database in a temporary folder, seeded with the literature library; the law is
bvk2007@1 (Beetstra, van der Hoef & Kuipers 2007). Reference values: F(0.1, 0) = 2.42878 and
F(0.4, 100) = 30.7416, the BVK 2007 formula evaluated independently from the published
coefficients (reference dossier drag_laws.md section 2.4 and its law_check_values.csv, 6
significant figures): tolerance 1e-5 relative covers that rounding. beta is checked against the
canonical identity beta = 18 mu phi eps F / d^2 (1e-13 relative: a few rounding errors).

Read-only opens: a database file 0444 in a directory 0555 is read without being written (size,
modification time and bytes unchanged); run as root (which ignores permissions), the check is
repeated as nobody through `setpriv --reuid=65534 --regid=65534 --clear-groups`.

Wrong arguments (bad-input findings P13, P16, P17, P20, P21, P25): a wrong type raises TypeError
and a wrong shape ValueError (both also DraglabError), naming the argument; never a ctypes or
AttributeError, never a silently dropped imaginary part; numpy shapes are kept (broadcast like
numpy), each element equal to the scalar F at the same inputs.

Environment: DRAGLAB_PYTHON_DIR (folder of draglab.py) and DRAGLAB_LIBRARY (path of libdraglab).
Runs with the standard library only; numpy is exercised if it can be imported.
"""

import array
import math
import os
import shutil
import subprocess
import sys
import tempfile
import threading
import unittest

sys.path.insert(0, os.environ.get("DRAGLAB_PYTHON_DIR", os.path.dirname(__file__)))
import draglab  # noqa: E402

try:
    import numpy
except ImportError:
    numpy = None

CHECK_TOLERANCE = 1e-5
ROUNDING_TOLERANCE = 1e-13


class PythonApiTest(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.TemporaryDirectory()
        self.db = draglab.Database(os.path.join(self.tmp.name, "test.db"))
        self.law = self.db.load("bvk2007@1")

    def tearDown(self):
        self.law.close()
        self.db.close()
        self.tmp.cleanup()

    def test_identity(self):
        self.assertEqual(self.law.name, "bvk2007")
        self.assertEqual(self.law.version, 1)
        self.assertEqual(self.law.reference, "bvk2007@1")
        self.assertEqual(self.law.form, "bvk2007")
        self.assertEqual(len(self.law.hash), 64)
        self.assertEqual(self.law.num_extra, 0)
        self.assertEqual(self.law.warning, "")
        (phi_min, phi_max), (re_min, re_max) = self.law.validity
        self.assertLess(phi_min, phi_max)
        self.assertLessEqual(re_min, re_max)
        self.assertTrue(draglab.version())

    def test_published_check_values(self):
        self.assertAlmostEqual(self.law.F(0.1, 0.0), 2.42878, delta=CHECK_TOLERANCE * 2.42878)
        self.assertAlmostEqual(self.law.F(0.4, 100.0), 30.7416, delta=CHECK_TOLERANCE * 30.7416)

    def test_conversions(self):
        phi, re = 0.4, 100.0
        F = self.law.F(phi, re)
        self.assertAlmostEqual(self.law.K(phi, re), F / (1 - phi),
                               delta=ROUNDING_TOLERANCE * F / (1 - phi))
        b = 18 * phi * (1 - phi) * F
        self.assertAlmostEqual(self.law.beta_d2_over_mu(phi, re), b, delta=ROUNDING_TOLERANCE * b)

    def test_beta_from_dimensional_inputs(self):
        eps_g, mu_g, rho_g, slip, d_p = 0.6, 1.8e-5, 1.2, 0.2, 5e-4
        phi = 1 - eps_g
        re = rho_g * eps_g * d_p * slip / mu_g
        expected = 18 * mu_g * phi * eps_g * self.law.F(phi, re) / d_p ** 2
        beta = self.law.beta(eps_g, mu_g, rho_g, slip, d_p, rho_s=2500.0)
        self.assertAlmostEqual(beta, expected, delta=ROUNDING_TOLERANCE * expected)
        self.assertAlmostEqual(self.law.dga(eps_g, mu_g, rho_g, slip, d_p, 2500.0), beta / phi,
                               delta=ROUNDING_TOLERANCE * beta / phi)
        with self.assertRaises(draglab.DraglabError) as caught:
            self.law.beta(eps_g, mu_g, rho_g, slip, d_p, rho_s=0.0)
        self.assertEqual(caught.exception.code, draglab.INVALID_ARGUMENT)
        self.assertIn("rho_s", caught.exception.message)

    def test_impossible_inputs_raise_never_nan(self):
        for phi, re, name in [(1.2, 10.0, "phi"), (math.nan, 10.0, "phi"), (0.3, -1.0, "Re"),
                              (0.3, math.nan, "Re"), (0.3, math.inf, "Re")]:
            with self.assertRaises(draglab.DraglabError) as caught:
                self.law.F(phi, re)
            self.assertEqual(caught.exception.code, draglab.INVALID_ARGUMENT)
            self.assertIn(name, caught.exception.message)
        with self.assertRaises(draglab.DraglabError) as caught:
            self.law.beta(1.2, 1.8e-5, 1.2, 0.1, 5e-4)
        self.assertEqual(caught.exception.code, draglab.INVALID_ARGUMENT)

    def test_range_policies(self):
        with self.assertRaises(draglab.DraglabError) as caught:
            self.law.F(0.05, 10.0)
        self.assertEqual(caught.exception.code, draglab.OUT_OF_VALIDITY)
        self.assertEqual(self.law.range_policy, "error")
        self.law.range_policy = "clamp"
        self.assertEqual(self.law.range_policy, "clamp")
        self.assertEqual(self.law.F(0.05, 10.0), self.law.F(0.1, 10.0))
        self.assertEqual(self.law.out_of_range_count, 1)
        self.law.range_policy = draglab.RANGE_EXTRAPOLATE
        self.assertLess(self.law.F(0.05, 10.0), self.law.F(0.1, 10.0))
        self.assertEqual(self.law.out_of_range_count, 2)
        with self.assertRaises(draglab.DraglabError):
            self.law.range_policy = "sometimes"
        with self.assertRaises(draglab.DraglabError):
            self.law.range_policy = 5
        loaded = self.db.load("bvk2007", range_policy="clamp")
        self.assertEqual(loaded.range_policy, "clamp")
        loaded.close()

    def test_array_path_with_lists_and_array_module(self):
        phi = [0.1, 0.25, 0.4, 0.6]
        re = [0.0, 3.0, 100.0, 1000.0]
        expected = [self.law.F(p, r) for p, r in zip(phi, re)]
        self.assertEqual(list(self.law.F_array(phi, re)), expected)
        out = self.law.F_array(array.array("d", phi), array.array("d", re))
        self.assertIsInstance(out, array.array)
        self.assertEqual(list(out), expected)
        self.assertEqual(len(self.law.F_array([], [])), 0)
        with self.assertRaises(draglab.DraglabError) as caught:
            self.law.F_array([0.3, 0.3, 0.3], [1.0, 2.0, math.nan])
        self.assertIn("index 2", caught.exception.message)
        with self.assertRaises(draglab.DraglabError):
            self.law.F_array([0.3, 0.3], [1.0])

    @unittest.skipIf(numpy is None, "numpy is not installed")
    def test_array_path_with_numpy(self):
        phi = numpy.linspace(0.1, 0.6, 11)
        re = numpy.linspace(0.0, 1000.0, 11)
        out = self.law.F_array(phi, re)
        self.assertIsInstance(out, numpy.ndarray)
        for i in range(11):
            self.assertEqual(out[i], self.law.F(float(phi[i]), float(re[i])))

    def test_wrong_argument_types_name_the_argument(self):
        cases = [
            (lambda: self.law.F("0.3", 10.0), "phi"),
            (lambda: self.law.F(None, 10.0), "phi"),
            (lambda: self.law.F(0.3, [10.0]), "re"),
            (lambda: self.law.F(0.3, 10 + 0j), "re"),
            (lambda: self.law.F(True, 10.0), "phi"),
            (lambda: self.law.K(0.3, "10"), "re"),
            (lambda: self.law.beta_d2_over_mu(object(), 10.0), "phi"),
            (lambda: self.law.beta("0.6", 1.8e-5, 1.2, 0.5, 5e-4), "eps_g"),
            (lambda: self.law.dga(0.6, 1.8e-5, 1.2, 0.5, None), "d_p"),
            (lambda: self.db.load(None), "reference"),
            (lambda: self.db.load(b"bvk2007"), "reference"),
            (lambda: draglab.Database(3), "path"),
            (lambda: setattr(self.law, "range_policy", 1.5), "range_policy"),
            (lambda: self.law.export(None), "format"),
            (lambda: self.law.F_array("0.3", [1.0]), "phi"),
            (lambda: self.law.F_array([0.3], None), "re"),
            (lambda: self.law.F_array([[0.3]], [1.0]), "phi"),
            (lambda: self.law.F_array([0.3, 1j], [1.0, 2.0]), "phi"),
        ]
        for call, name in cases:
            with self.assertRaises(TypeError) as caught:
                call()
            self.assertIsInstance(caught.exception, draglab.DraglabError)
            self.assertEqual(caught.exception.code, draglab.INVALID_ARGUMENT)
            self.assertIn(name, caught.exception.message)
        # Every real type is taken: ints, fractions, the array module, numpy scalars.
        import fractions
        self.assertEqual(self.law.F(fractions.Fraction(3, 10), 10), self.law.F(0.3, 10.0))

    def test_list_shapes(self):
        with self.assertRaises(ValueError) as caught:
            self.law.F_array([0.3, 0.3], [1.0])
        self.assertIn("lengths", caught.exception.message)
        # A scalar against a sequence is repeated.
        out = self.law.F_array(0.3, [1.0, 10.0])
        self.assertEqual(list(out), [self.law.F(0.3, 1.0), self.law.F(0.3, 10.0)])

    @unittest.skipIf(numpy is None, "numpy is not installed")
    def test_numpy_shapes_and_types(self):
        phi = numpy.array([[0.1, 0.2], [0.3, 0.4]])
        re = numpy.array([0.0, 100.0])
        out = self.law.F_array(phi, re)  # broadcast: (2, 2) against (2,)
        self.assertEqual(out.shape, (2, 2))
        for i in range(2):
            for j in range(2):
                self.assertEqual(out[i, j], self.law.F(phi[i, j], re[j]))
        self.assertEqual(self.law.F_array(numpy.float64(0.3), numpy.array(10.0)).shape, ())
        self.assertEqual(self.law.F_array(phi.T, 50.0).shape, (2, 2))  # non-contiguous
        self.assertEqual(self.law.F_array(numpy.zeros((0, 3)) + 0.3, 1.0).shape, (0, 3))
        with self.assertRaises(ValueError) as caught:
            self.law.F_array(phi, numpy.array([1.0, 2.0, 3.0]))
        self.assertIn("(2, 2)", caught.exception.message)
        self.assertIn("(3,)", caught.exception.message)
        with self.assertRaises(TypeError) as caught:
            self.law.F_array(numpy.array([0.3 + 0.1j]), numpy.array([1.0]))
        self.assertIn("complex", caught.exception.message)
        with self.assertRaises(TypeError):
            self.law.F_array(numpy.array(["0.3"]), numpy.array([1.0]))
        with self.assertRaises(TypeError):
            self.law.F(numpy.complex128(0.3), 1.0)
        self.assertEqual(self.law.F(numpy.float32(0.25), numpy.int64(10)), self.law.F(0.25, 10.0))
        bad = numpy.array([[0.3, 0.3], [0.3, numpy.nan]])
        with self.assertRaises(draglab.DraglabError) as caught:
            self.law.F_array(bad, 1.0)
        self.assertIn("(1, 1)", caught.exception.message)

    def test_unknown_law(self):
        with self.assertRaises(draglab.DraglabError) as caught:
            self.db.load("no_such_law")
        self.assertEqual(caught.exception.code, draglab.NOT_FOUND)

    def test_law_outlives_database_and_closed_handles_raise(self):
        value = self.law.F(0.4, 100.0)
        self.db.close()
        self.assertEqual(self.law.F(0.4, 100.0), value)
        with self.assertRaises(draglab.DraglabError):
            self.db.load("bvk2007")
        self.law.close()
        with self.assertRaises(draglab.DraglabError):
            self.law.F(0.4, 100.0)

    def test_context_managers(self):
        path = os.path.join(self.tmp.name, "second.db")
        with draglab.Database(path) as db:
            with db.load("bvk2007@1") as law:
                self.assertEqual(law.F(0.4, 100.0), self.law.F(0.4, 100.0))
            self.assertIsNone(law._handle)
        self.assertIsNone(db._handle)

    def test_not_a_database(self):
        path = os.path.join(self.tmp.name, "garbage.db")
        with open(path, "wb") as f:
            f.write(bytes((i * 37 + 11) % 256 for i in range(4096)))
        with self.assertRaises(draglab.DraglabError) as caught:
            draglab.Database(path)
        self.assertEqual(caught.exception.code, draglab.NOT_A_DATABASE)

    def _read_only_installation(self):
        """A closed database made read-only like a shared installation: file 0444 in a directory
        0555 (inside a directory others may enter). Returns the database path."""
        shared = os.path.join(self.tmp.name, "shared")
        os.mkdir(shared)
        path = os.path.join(shared, "shared.db")
        draglab.Database(path).close()
        os.chmod(path, 0o444)
        os.chmod(shared, 0o555)
        os.chmod(self.tmp.name, 0o755)
        return path

    @staticmethod
    def _fingerprint(path):
        """Size, modification time (ns) and bytes: what "nothing was written" compares."""
        st = os.stat(path)
        with open(path, "rb") as f:
            return st.st_size, st.st_mtime_ns, f.read()

    def test_read_only(self):
        path = self._read_only_installation()
        before = self._fingerprint(path)
        with draglab.Database(path, read_only=True) as db:
            with db.load("bvk2007@1") as law:
                self.assertEqual(law.F(0.4, 100.0), self.law.F(0.4, 100.0))
        self.assertEqual(self._fingerprint(path), before)
        missing = os.path.join(self.tmp.name, "absent.db")
        with self.assertRaises(draglab.DraglabError) as caught:
            draglab.Database(missing, read_only=True)
        self.assertEqual(caught.exception.code, draglab.NOT_FOUND)
        self.assertIn(missing, caught.exception.message)
        self.assertFalse(os.path.exists(missing))
        with self.assertRaises(draglab.DraglabError) as caught:
            draglab.Database(os.path.join(self.tmp.name, "nowhere", "x.db"), read_only=True)
        self.assertEqual(caught.exception.code, draglab.INVALID_ARGUMENT)

    @unittest.skipUnless(hasattr(os, "geteuid") and os.geteuid() == 0 and shutil.which("setpriv"),
                         "needs root and setpriv to run a check as an unprivileged user")
    def test_read_only_as_an_unprivileged_user(self):
        # Root ignores file permissions: the solver's view is checked as nobody (uid/gid 65534).
        path = self._read_only_installation()
        before = self._fingerprint(path)
        entries = sorted(os.listdir(os.path.dirname(path)))
        script = (
            "import os, sys\n"
            "sys.path.insert(0, os.environ['DRAGLAB_TEST_MODULE_DIR'])\n"
            "import draglab\n"
            "path = sys.argv[1]\n"
            "assert not os.access(os.path.dirname(path), os.W_OK), 'directory is writable'\n"
            "with draglab.Database(path, read_only=True) as db:\n"
            "    print(repr(db.load('bvk2007@1').F(0.4, 100.0)))\n"
            "try:\n"
            "    draglab.Database(path)\n"
            "    print('read-write open was not refused')\n"
            "except draglab.DraglabError as e:\n"
            "    print('refused', e.code)\n")
        env = dict(os.environ)
        env["DRAGLAB_TEST_MODULE_DIR"] = os.path.dirname(os.path.abspath(draglab.__file__))
        env["DRAGLAB_LIBRARY"] = draglab.library_path
        result = subprocess.run(
            ["setpriv", "--reuid=65534", "--regid=65534", "--clear-groups", sys.executable,
             "-c", script, path], env=env, cwd="/", stdout=subprocess.PIPE,
            stderr=subprocess.STDOUT, universal_newlines=True)
        if result.returncode != 0 and "cannot load libdraglab" in result.stdout:
            self.skipTest("nobody cannot read the library: " + result.stdout)
        self.assertEqual(result.returncode, 0, result.stdout)
        lines = result.stdout.split()
        self.assertEqual(float(lines[0]), self.law.F(0.4, 100.0), result.stdout)
        self.assertEqual(lines[1:], ["refused", str(draglab.DATABASE_ERROR)], result.stdout)
        self.assertEqual(self._fingerprint(path), before)
        self.assertEqual(sorted(os.listdir(os.path.dirname(path))), entries)

    def test_threads_share_a_law(self):
        points = [(0.1 + 0.05 * (i % 10), 10.0 * i) for i in range(50)]
        serial = [self.law.F(p, r) for p, r in points]
        mismatches = []

        def work():
            for _ in range(20):
                if [self.law.F(p, r) for p, r in points] != serial:
                    mismatches.append(1)

        threads = [threading.Thread(target=work) for _ in range(4)]
        for t in threads:
            t.start()
        for t in threads:
            t.join()
        self.assertEqual(mismatches, [])

    def test_export(self):
        c = self.law.export("c")
        self.assertIn("double bvk2007_v1_F(double phi, double re)", c)
        self.assertIn(self.law.hash, c)
        self.assertIn("module bvk2007_v1_drag", self.law.export("fortran"))
        self.assertIn('"content_hash"', self.law.export("json"))
        with self.assertRaises(draglab.DraglabError):
            self.law.export("pascal")


if __name__ == "__main__":
    unittest.main(verbosity=2)
