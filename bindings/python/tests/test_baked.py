"""Baked maps through the binding: Scene.bake and Context.load_baked from
bytes, other buffers and files give the baked scene's ranges bit for bit on
the built-in backend and the same hits on Embree and Vulkan; the loaded scene
holds its blob or mapping until its destroy has run; corrupted, unreadable
and refused maps raise rangecast.Error with the library's message."""

import gc
import os
import shutil
import sys
import tempfile
import unittest
import weakref

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from test_rangecast import StatusAssertions, box, plane_x, random_poses, uv_sphere  # noqa: E402

import rangecast  # noqa: E402
from rangecast import Error  # noqa: E402
from rangecast import _ffi as F  # noqa: E402

ATTRS = ("ranges", "hits", "normals", "prim_ids", "geom_ids")
CHECKSUM_AT = 20  # the header's checksum field (docs/baked-map.md)


def three_meshes(ctx, origin=(0.0, 0.0, 0.0)):
    """A committed scene of a sphere, a box inside it and a wall: three geometries."""
    scene = ctx.create_scene(max_triangles=20000, max_geometries=3, max_vertices=8, max_copied_triangles=12,
                             origin=origin)
    scene.add_mesh(*uv_sphere(20.0, 60, 120))
    scene.add_mesh(*box((2, -1, -1), (4, 1, 1)), copy=True)
    scene.add_mesh(*plane_x(-6.0, half=3.0))
    scene.commit()
    return scene


def fd_count():
    return len(os.listdir("/proc/self/fd")) if os.path.isdir("/proc/self/fd") else None


class BakedBase(StatusAssertions, unittest.TestCase):
    def setUp(self):
        self.ctx = rangecast.Context(backend="bvh", threads=2)
        self.scene = three_meshes(self.ctx)
        self.lidar = self.ctx.preset_sensor("vlp16-360")
        self.poses = random_poses(4, seed=5)
        self.want = self.ctx.simulate(self.scene, self.lidar, self.poses, ATTRS)
        self.dir = tempfile.mkdtemp(prefix="rangecast-baked-")

    def tearDown(self):
        self.ctx.close()
        shutil.rmtree(self.dir)

    def assertSameScan(self, scene):
        got = self.ctx.simulate(scene, self.lidar, self.poses, ATTRS)
        for k in ATTRS:
            np.testing.assert_array_equal(got[k], self.want[k], err_msg=k)


class TestBakeAndLoad(BakedBase):
    def test_bytes_load_bit_identical_and_in_place(self):
        blob = self.scene.bake()
        self.assertIsInstance(blob, bytes)
        self.assertEqual(blob[:8], b"\x89RCMAP\r\n")
        self.assertEqual(self.scene.bake(), blob, "baking twice gave other bytes")
        loaded = self.ctx.load_baked(blob)
        info = loaded.info
        self.assertEqual((info["geometry_count"], info["committed"]), (3, True))
        self.assertEqual(info["triangle_count"], self.scene.info["triangle_count"])
        np.testing.assert_array_equal(loaded.bounds, self.scene.bounds)
        self.assertSameScan(loaded)
        # bytes cannot change: the scene reads them in place
        if np.frombuffer(blob, np.uint8).ctypes.data % F.BAKED_ALIGN == 0:
            self.assertIs(loaded._blob.array.base, blob)
        # ... and holds them once the caller lets go
        del blob
        gc.collect()
        self.assertSameScan(loaded)
        # a loaded scene bakes again to the same bytes
        self.assertEqual(loaded.bake(), self.scene.bake())

    def test_other_buffers_are_copied(self):
        blob = self.scene.bake()
        raw = bytearray(len(blob) + 1)
        raw[1:] = blob
        view = memoryview(raw)[1:]  # one byte off any alignment
        loaded = self.ctx.load_baked(view)
        view.release()
        raw[:] = bytes(len(raw))  # the caller's buffer changes: the scene's copy does not
        del raw
        gc.collect()
        self.assertSameScan(loaded)
        arr = np.frombuffer(blob, np.uint8).copy()
        self.assertSameScan(self.ctx.load_baked(arr))

    def test_file_load_maps_and_keeps_the_mapping(self):
        path = os.path.join(self.dir, "map.rcmap")
        size = self.scene.bake(path)
        self.assertEqual(size, os.path.getsize(path))
        self.assertEqual(os.listdir(self.dir), ["map.rcmap"], "a temporary file was left")
        with open(path, "rb") as f:
            self.assertEqual(f.read(), self.scene.bake())
        fds = fd_count()
        loaded = self.ctx.load_baked(path)
        self.assertSameScan(loaded)
        # baking over the file renames a new one into place: the mapped one stays
        self.assertEqual(self.scene.bake(path), size)
        self.assertSameScan(loaded)
        # a pathlib path, with the checksum skipped
        import pathlib
        self.assertSameScan(self.ctx.load_baked(pathlib.Path(path), skip_checksum=True))
        gc.collect()
        loaded.close()
        if fds is not None:
            self.assertEqual(fd_count(), fds, "closing the scene left the mapping's descriptor open")
        self.assertStatus(F.ERR_INVALID_HANDLE, "Scene is closed", lambda: loaded.info)

    def test_dropped_scene_waits_for_its_destroy(self):
        path = os.path.join(self.dir, "map.rcmap")
        self.scene.bake(path)
        fds = fd_count()
        loaded = self.ctx.load_baked(path)
        world = self.ctx.create_scene(max_triangles=0, max_geometries=0, max_instances=1)
        world.add_instance(loaded, [1, 0, 0, 0, 0, 0, 1])
        world.commit()
        want = self.ctx.simulate(world, self.lidar, self.poses, ATTRS)
        del loaded  # the world holds it, and it its mapping
        gc.collect()
        got = self.ctx.simulate(world, self.lidar, self.poses, ATTRS)
        for k in ATTRS:
            np.testing.assert_array_equal(got[k], want[k], err_msg=k)
        del world  # both go, the instanced one after the world that instanced it
        gc.collect()
        if fds is not None:
            self.assertEqual(fd_count(), fds, "the dropped scene's mapping is still open")

    def test_scene_dropped_during_a_call_keeps_its_mapping_until_destroyed(self):
        path = os.path.join(self.dir, "map.rcmap")
        self.scene.bake(path)
        fds = fd_count()
        doomed = [self.ctx.load_baked(path)]
        blob = weakref.ref(doomed[0]._blob)
        held = []

        def progress(stage, fraction):
            if doomed:
                doomed.pop()  # the last reference, dropped inside the C call: its destroy waits
                gc.collect()
                held.append(blob() is not None)
        self.ctx.mesh_scene(*plane_x(1.0), progress=progress)
        self.assertEqual(held, [True], "the blob went before the scene's destroy")
        gc.collect()
        self.assertIsNone(blob(), "the destroyed scene's blob is still held")
        if fds is not None:
            self.assertEqual(fd_count(), fds, "the dropped scene's mapping is still open")

    def test_origin_and_double_poses(self):
        origin = (512000.0, 5400000.0, 30.0)
        with rangecast.Context(backend="bvh", threads=2) as ctx:
            scene = three_meshes(ctx, origin)
            poses = self.poses.astype(np.float64)
            poses[:, :3] += origin
            lidar = ctx.preset_sensor("vlp16")
            want = ctx.simulate(scene, lidar, poses, ATTRS)
            got = ctx.simulate(ctx.load_baked(scene.bake()), lidar, poses, ATTRS)
            for k in ATTRS:
                np.testing.assert_array_equal(got[k], want[k], err_msg=k)

    def other_backend(self, backend):
        """The baked map on another backend: the built-in one's hits; baking
        there is refused (the map holds the built-in backend's tree)."""
        if not rangecast.backend_available(backend):
            self.skipTest("the %s backend is not built into this library" % backend)
        blob = self.scene.bake()
        try:
            ctx = rangecast.Context(backend=backend, threads=2)
        except Error as e:
            if e.status != F.ERR_UNSUPPORTED:
                raise
            self.skipTest("%s is built in, but: %s" % (backend, e))
        with ctx:
            loaded = ctx.load_baked(blob)
            del blob
            gc.collect()
            got = ctx.simulate(loaded, ctx.preset_sensor("vlp16-360"), self.poses, ATTRS)
            np.testing.assert_array_equal(got["hits"], self.want["hits"])
            np.testing.assert_array_equal(got["geom_ids"], self.want["geom_ids"])
            np.testing.assert_allclose(got["ranges"], self.want["ranges"], rtol=1e-5)
            self.assertStatus(F.ERR_UNSUPPORTED, "RC_BACKEND_BVH", loaded.bake)
            self.assertStatus(F.ERR_UNSUPPORTED, "RC_BACKEND_BVH", ctx.mesh_scene(*plane_x(2.0)).bake)

    def test_embree_loads_the_same_hits(self):
        self.other_backend("embree")

    def test_vulkan_loads_the_same_hits(self):
        self.other_backend("vulkan")


class TestGoldenMap(unittest.TestCase):
    def test_the_c_suites_golden_map(self):
        # tests/data/box_room.rcmap, baked by tests/test_baked.c: a closed
        # room x -2..4, y -3..5, z -1..2 that every target reads
        path = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "..", "tests", "data",
                            "box_room.rcmap")
        if not os.path.exists(path):
            self.skipTest("%s is not here (not a source checkout)" % path)
        dirs = [[1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1]]
        with rangecast.Context(backend="bvh", threads=1) as ctx:
            room = ctx.load_baked(path)
            r = ctx.simulate(room, ctx.rays_sensor(dirs, 0.01, 100.0), [0, 0, 0, 0, 0, 0, 1])["ranges"]
            np.testing.assert_array_equal(r[0, 0], np.array([4, 2, 5, 3, 2, 1], np.float32))


class TestBakedErrors(BakedBase):
    def test_corrupted_file_names_the_checksum(self):
        path = os.path.join(self.dir, "map.rcmap")
        size = self.scene.bake(path)
        with open(path, "r+b") as f:
            f.seek(size // 2)
            b = f.read(1)
            f.seek(size // 2)
            f.write(bytes([b[0] ^ 0x10]))
        fds = fd_count()
        self.assertStatus(F.ERR_CORRUPT_DATA, "checksum", self.ctx.load_baked, path)
        if fds is not None:
            self.assertEqual(fd_count(), fds, "a failed load left the mapping's descriptor open")

    def test_skip_checksum_trusts_the_bytes_not_the_structure(self):
        blob = bytearray(self.scene.bake())
        blob[CHECKSUM_AT] ^= 0xFF
        self.assertStatus(F.ERR_CORRUPT_DATA, "checksum", self.ctx.load_baked, blob)
        self.assertSameScan(self.ctx.load_baked(blob, skip_checksum=True))
        self.assertStatus(F.ERR_CORRUPT_DATA, "the first 8 bytes", self.ctx.load_baked, b"\0" * 256, skip_checksum=True)

    def test_loaded_scene_is_read_only(self):
        loaded = self.ctx.load_baked(self.scene.bake())
        msg = "loaded from a baked map and is read-only"
        self.assertStatus(F.ERR_MISUSE, msg, loaded.add_mesh, *plane_x(1.0))
        self.assertStatus(F.ERR_MISUSE, msg, loaded.update_mesh, 0)
        self.assertStatus(F.ERR_MISUSE, msg, loaded.add_instance, self.scene)
        self.assertSameScan(loaded)

    def test_refused_scenes_and_sources(self):
        fresh = self.ctx.create_scene(max_triangles=2)
        fresh.add_mesh(*plane_x(1.0))
        self.assertStatus(F.ERR_NOT_COMMITTED, "commit it before baking", fresh.bake)
        world = self.ctx.create_scene(max_triangles=0, max_geometries=0, max_instances=1)
        world.add_instance(self.scene)
        world.commit()
        self.assertStatus(F.ERR_UNSUPPORTED, "instance", world.bake)
        missing = os.path.join(self.dir, "none.rcmap")
        self.assertStatus(F.ERR_IO, "none.rcmap", self.ctx.load_baked, missing)
        self.assertStatus(F.ERR_IO, "cannot write", self.scene.bake, os.path.join(missing, "x.rcmap"))
        self.assertEqual(os.listdir(self.dir), [], "a failed bake left a file")
        empty = os.path.join(self.dir, "empty.rcmap")
        open(empty, "wb").close()
        self.assertStatus(F.ERR_CORRUPT_DATA, "empty", self.ctx.load_baked, empty)
        self.assertStatus(F.ERR_INVALID_ARGUMENT, "source must be a path", self.ctx.load_baked, 42)
        self.assertStatus(F.ERR_CORRUPT_DATA, "bytes", self.ctx.load_baked, self.scene.bake()[:-64])
        self.ctx.close()
        self.assertStatus(F.ERR_INVALID_HANDLE, "context is closed", self.ctx.load_baked, missing)


if __name__ == "__main__":
    unittest.main()
