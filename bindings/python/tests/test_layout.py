"""The binding's ctypes structs against the C layout the library pins in
tests/abi/<lp64|ilp32>.txt (checked on the C side by the abi_layout test):
every struct's size and alignment, every field's offset and size. A field
added to the header without the binding fails here."""

import ctypes
import os
import sys
import unittest

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, ".."))
from rangecast import _ffi as F  # noqa: E402

ABI_DIR = os.environ.get("RANGECAST_ABI_DIR", os.path.join(HERE, "..", "..", "..", "tests", "abi"))
# public structs the binding does not use (Vulkan interop stays in C)
UNBOUND = {"rc_device_results"}


def golden():
    """{struct: (size, align, {field: (offset, size)})} from the golden file."""
    name = "lp64.txt" if ctypes.sizeof(ctypes.c_void_p) == 8 else "ilp32.txt"
    structs, cur = {}, None
    with open(os.path.join(ABI_DIR, name)) as f:
        for line in f:
            words = line.split()
            if not words or words[0] == "#" or words[0] == "pad":
                continue
            if not line.startswith(" "):
                cur = words[0]
                structs[cur] = (int(words[2]), int(words[4]), {})
            else:
                structs[cur][2][words[0]] = (int(words[1]), int(words[2]))
    return structs


class TestLayout(unittest.TestCase):
    def test_structs_match_the_c_layout(self):
        want = golden()
        self.assertGreater(len(want), 10)
        for cname, (size, align, fields) in want.items():
            if cname in UNBOUND:
                continue
            with self.subTest(struct=cname):
                self.assertIn(cname, F.STRUCTS, "the binding lacks %s" % cname)
                cls = F.STRUCTS[cname]
                self.assertEqual(ctypes.sizeof(cls), size)
                self.assertEqual(ctypes.alignment(cls), align)
                got = {name: (getattr(cls, name).offset, getattr(cls, name).size) for name, _ in cls._fields_}
                self.assertEqual(got, fields)

    def test_every_bound_struct_is_pinned(self):
        want = golden()
        for cname in F.STRUCTS:
            if cname != "rc_pose_d":  # the header's double pose is not in the golden files
                self.assertIn(cname, want)
        self.assertEqual(ctypes.sizeof(F.PoseD), 56)


    def test_package_version_is_the_library_version(self):
        import rangecast
        with open(os.path.join(HERE, "..", "pyproject.toml")) as f:
            line = next(ln for ln in f if ln.startswith("version"))
        self.assertEqual(line.split("=")[1].strip().strip('"'), rangecast.version())


if __name__ == "__main__":
    unittest.main()
