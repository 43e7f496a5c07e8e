"""The Python binding against known answers: analytic scenes, every
attribute, instances, thread-count independence, backend parity, and each bad
input's status and message (with nothing written). Run with
`python3 -m unittest discover -s bindings/python/tests` after `make build`
(ctest runs it as python_binding)."""

import math
import os
import sys
import unittest

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
import rangecast  # noqa: E402
from rangecast import Error  # noqa: E402
from rangecast import _ffi as F  # noqa: E402

IDENTITY = [0, 0, 0, 0, 0, 0, 1]


def plane_x(d, half=50.0):
    """Two triangles of the plane x = d, facing -x."""
    v = np.array([[d, -half, -half], [d, half, -half], [d, half, half], [d, -half, half]], np.float32)
    t = np.array([[0, 1, 2], [0, 2, 3]], np.uint32)
    return v, t


def box(lo, hi):
    """A closed axis-aligned box, 12 triangles sharing 8 corners."""
    v = np.array([[x, y, z] for z in (lo[2], hi[2]) for y in (lo[1], hi[1]) for x in (lo[0], hi[0])], np.float32)
    quads = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
    t = np.array([tri for a, b, c, d in quads for tri in ((a, b, c), (a, c, d))], np.uint32)
    return v, t


def uv_sphere(radius, rings=40, segments=80):
    v = [[0, 0, -radius]]
    for i in range(1, rings):
        phi = -math.pi / 2 + math.pi * i / rings
        for j in range(segments):
            th = 2 * math.pi * j / segments
            v.append([radius * math.cos(phi) * math.cos(th), radius * math.cos(phi) * math.sin(th),
                      radius * math.sin(phi)])
    v.append([0, 0, radius])
    t = []
    for j in range(segments):
        t.append([0, 1 + (j + 1) % segments, 1 + j])
    for i in range(rings - 2):
        a, b = 1 + i * segments, 1 + (i + 1) * segments
        for j in range(segments):
            j1 = (j + 1) % segments
            t += [[a + j, a + j1, b + j1], [a + j, b + j1, b + j]]
    top = len(v) - 1
    last = 1 + (rings - 2) * segments
    for j in range(segments):
        t.append([last + j, last + (j + 1) % segments, top])
    return np.array(v, np.float32), np.array(t, np.uint32)


def spherical_dirs(info_theta, info_phi):
    th = info_theta[0] + info_theta[1] * np.arange(info_theta[2])
    ph = info_phi[0] + info_phi[1] * np.arange(info_phi[2])
    P, T = np.meshgrid(ph, th, indexing="ij")
    return np.stack([np.cos(P) * np.cos(T), np.cos(P) * np.sin(T), np.sin(P)], axis=-1)


def random_poses(n=6, dtype=np.float32, seed=3):
    """n poses within 8 m of the origin, uniformly rotated."""
    rng = np.random.default_rng(seed)
    q = rng.normal(size=(n, 4))
    q /= np.linalg.norm(q, axis=1, keepdims=True)
    return np.concatenate([rng.uniform(-8, 8, (n, 3)), q], axis=1).astype(dtype)


class StatusAssertions(object):
    """assertStatus for a TestCase (a mixin: other test files import it)."""

    def assertStatus(self, status, text, fn, *args, **kw):
        with self.assertRaises(Error) as cm:
            fn(*args, **kw)
        self.assertEqual(cm.exception.status, status, str(cm.exception))
        self.assertIn(text, str(cm.exception))
        return cm.exception


class Base(unittest.TestCase):
    def setUp(self):
        self.ctx = rangecast.Context(backend="bvh", threads=2)

    def tearDown(self):
        self.ctx.close()


class TestAnalytic(Base):
    THETA = (-0.6, 0.01, 121)
    PHI = (-0.3, 0.05, 13)

    def test_plane_every_attribute(self):
        d = 7.5
        scene = self.ctx.mesh_scene(*plane_x(d))
        lidar = self.ctx.spherical_sensor(self.THETA, self.PHI, 0.1, 100.0)
        self.assertEqual(lidar.info["rows"], 13)
        self.assertEqual(lidar.info["columns"], 121)
        scan = self.ctx.simulate(scene, lidar, IDENTITY, list(rangecast.ATTRIBUTES))
        dirs = spherical_dirs(self.THETA, self.PHI)
        want = d / dirs[..., 0]
        self.assertEqual(scan["ranges"].shape, (1, 13, 121))
        self.assertEqual(scan["points"].shape, (1, 13, 121, 3))
        np.testing.assert_allclose(scan["ranges"][0], want, rtol=2e-6)
        self.assertTrue((scan["hits"] == 1).all())
        np.testing.assert_allclose(scan["points"][0], dirs * want[..., None], rtol=2e-6, atol=2e-6)
        np.testing.assert_allclose(scan["normals"][0], np.broadcast_to([-1, 0, 0], dirs.shape), atol=1e-6)
        self.assertTrue(set(np.unique(scan["prim_ids"])) <= {0, 1})
        self.assertTrue((scan["geom_ids"] == 0).all())
        self.assertTrue((scan["inst_ids"] == rangecast.INVALID_ID).all())

    def test_rep117_misses_and_too_near(self):
        scene = self.ctx.mesh_scene(*plane_x(3.0))
        lidar = self.ctx.spherical_sensor((0.0, 0.01, 3), (0.0, 0.01, 1), 0.1, 2.0)
        far = self.ctx.simulate(scene, lidar, IDENTITY, ("hits", "ranges", "points", "prim_ids"))
        self.assertTrue(np.isposinf(far["ranges"]).all())
        self.assertTrue((far["hits"] == 0).all())
        self.assertTrue(np.isnan(far["points"]).all())
        self.assertTrue((far["prim_ids"] == rangecast.INVALID_ID).all())
        near = self.ctx.spherical_sensor((0.0, 0.01, 3), (0.0, 0.01, 1), 5.0, 50.0)
        out = self.ctx.simulate(scene, near, IDENTITY, ("hits", "ranges"))
        self.assertTrue(np.isneginf(out["ranges"]).all())
        self.assertTrue((out["hits"] == 0).all())

    def test_closed_box_room_has_no_escapes(self):
        scene = self.ctx.mesh_scene(*box((-4, -3, -1), (6, 3, 2)), copy=True)
        lidar = self.ctx.preset_sensor("vlp16")
        poses = np.array([[0, 0, 0, 0, 0, 0, 1], [1.5, -1, 0.5] + list(rangecast.quaternion_from_euler(0.1, -0.2, 2.0))],
                         np.float32)
        scan = self.ctx.simulate(scene, lidar, poses, ("ranges", "points", "hits"))
        self.assertEqual(scan["ranges"].shape, (2, 16, 900))
        self.assertTrue((scan["hits"] == 1).all(), "a ray left the closed room")
        # pose 0 is unrotated: every point lies on a wall of the box
        p = scan["points"][0].reshape(-1, 3)
        on_wall = np.min(np.abs(np.concatenate([p - [-4, -3, -1], p - [6, 3, 2]], axis=1)), axis=1)
        self.assertLess(on_wall.max(), 1e-4)
        np.testing.assert_allclose(np.linalg.norm(scan["points"], axis=-1), scan["ranges"], rtol=1e-5)

    def test_2d_scanner_presets_in_a_room(self):
        # an upright 2-D scanner at the room's centre: column j looks along
        # angle_min + j * increment (a ROS LaserScan), each ray meets a wall
        scene = self.ctx.mesh_scene(*box((-2, -3, -1), (2, 3, 1)), copy=True)
        for name, angle_min, step, count in (("ust-10lx", -135.0, 0.25, 1081), ("lds-01", 0.0, 1.0, 360)):
            scan = self.ctx.simulate(scene, self.ctx.preset_sensor(name), IDENTITY, ("ranges",))["ranges"]
            self.assertEqual(scan.shape, (1, 1, count))
            theta = np.radians(angle_min + step * np.arange(count))
            with np.errstate(divide="ignore"):
                want = np.minimum(2.0 / np.abs(np.cos(theta)), 3.0 / np.abs(np.sin(theta)))
            reach = {"ust-10lx": 10.0, "lds-01": 3.5}[name]
            near = np.abs(want - reach) > 1e-3
            inside = near & (want < reach)
            np.testing.assert_allclose(scan[0, 0][inside], want[inside], rtol=1e-5)
            self.assertTrue(np.isposinf(scan[0, 0][near & (want > reach)]).all())

    def test_sensor_inside_sphere(self):
        scene = self.ctx.mesh_scene(*uv_sphere(10.0))
        lidar = self.ctx.preset_sensor("vlp16-360")
        scan = self.ctx.simulate(scene, lidar, IDENTITY, ("ranges",))
        r = scan["ranges"]
        self.assertTrue(np.isfinite(r).all())
        # the faceted sphere lies between its inscribed and circumscribed radii
        self.assertGreater(r.min(), 10.0 * math.cos(math.pi / 40) * math.cos(math.pi / 80) - 1e-4)
        self.assertLessEqual(r.max(), 10.0 + 1e-4)

    def test_pinhole_optical_frame_and_rays_sensors(self):
        scene = self.ctx.mesh_scene(*plane_x(4.0))
        # the optical frame (z forward, x right, y down) mounted looking along the base's x
        optical = [0, 0, 0] + list(rangecast.quaternion_from_euler(-math.pi / 2, 0, -math.pi / 2))
        cam = self.ctx.pinhole_sensor(5, 3, 2.0, 2.0, 2.0, 1.0, 0.1, 20.0, optical_frame=True, mounting=optical)
        out = self.ctx.simulate(scene, cam, IDENTITY, ("points", "ranges"))
        self.assertEqual(out["ranges"].shape, (1, 3, 5))
        # pixel (u = cx, v = cy) looks along the base's x axis; u grows to the
        # right (base -y) and v downwards (base -z)
        np.testing.assert_allclose(out["points"][0, 1, 2], [0, 0, 4.0], atol=1e-5)
        np.testing.assert_allclose(out["points"][0, 0, 4], [4.0, -2.0, 4.0], rtol=1e-5)
        np.testing.assert_allclose(out["points"][0, ..., 2], np.full((3, 5), 4.0), rtol=1e-5)
        dirs = np.array([[1, 0, 0], [1, 1, 0], [0, 1, 0]], np.float32)
        o1dn = self.ctx.rays_sensor(dirs, 0.1, 100.0)
        r = self.ctx.simulate(scene, o1dn, IDENTITY)["ranges"]
        self.assertEqual(r.shape, (1, 1, 3))
        np.testing.assert_allclose(r[0, 0, :2], [4.0, 4.0 * math.sqrt(2)], rtol=1e-6)
        self.assertTrue(np.isposinf(r[0, 0, 2]))
        ondn = self.ctx.rays_sensor(dirs[:2], 0.1, 100.0, origins=[[1, 0, 0], [3, -1, 0]], shape=(2, 1))
        r = self.ctx.simulate(scene, ondn, IDENTITY)["ranges"]
        self.assertEqual(r.shape, (1, 2, 1))
        np.testing.assert_allclose(r[0, :, 0], [3.0, math.sqrt(2)], rtol=1e-6)

    def test_cylindrical_and_mounting(self):
        scene = self.ctx.mesh_scene(*plane_x(6.0))
        cyl = self.ctx.cylindrical_sensor((0.0, 0.0, 1), 3, 1.0, 1.0, 0.1, 100.0)
        r = self.ctx.simulate(scene, cyl, IDENTITY)["ranges"][0, :, 0]
        np.testing.assert_allclose(r, [6 * math.sqrt(2), 6.0, 6 * math.sqrt(2)], rtol=1e-6)
        cyl.set_mounting([2.0, 0, 0, 0, 0, 0, 1])
        r = self.ctx.simulate(scene, cyl, IDENTITY)["ranges"][0, 1, 0]
        self.assertAlmostEqual(float(r), 4.0, places=5)


class TestNoise(Base):
    def test_noise_statistics_dropout_and_reproducibility(self):
        scene = self.ctx.mesh_scene(*plane_x(20.0, half=500.0))
        rng = np.random.default_rng(1)
        dirs = np.concatenate([np.ones((20000, 1)), rng.uniform(-0.5, 0.5, (20000, 2))], axis=1)
        s = self.ctx.rays_sensor(dirs, 0.1, 100.0)
        clean = self.ctx.simulate(scene, s, IDENTITY)["ranges"]
        s.set_noise(sigma=0.05, mean=0.01, seed=4)
        a = self.ctx.simulate(scene, s, IDENTITY, ("ranges", "points"))
        res = (a["ranges"] - clean).ravel()
        self.assertLess(abs(res.mean() - 0.01), 5 * 0.05 / math.sqrt(res.size))
        self.assertLess(abs(res.std() - 0.05), 0.0025)
        np.testing.assert_allclose(np.linalg.norm(a["points"], axis=-1), a["ranges"], rtol=1e-5)
        b = self.ctx.simulate(scene, s, IDENTITY)["ranges"]
        self.assertFalse(np.array_equal(a["ranges"], b), "a second call drew the same noise")
        s.set_noise(sigma=0.05, mean=0.01, seed=4)
        np.testing.assert_array_equal(self.ctx.simulate(scene, s, IDENTITY)["ranges"], a["ranges"])
        s.set_noise(dropout=0.25, seed=1)
        hits = self.ctx.simulate(scene, s, IDENTITY, ("hits",))["hits"]
        self.assertLess(abs(1.0 - hits.mean() - 0.25), 0.02)
        s.set_noise()
        np.testing.assert_array_equal(self.ctx.simulate(scene, s, IDENTITY)["ranges"], clean)
        with self.assertRaises(Error) as cm:
            s.set_noise(dropout=2.0)
        self.assertEqual(cm.exception.status, F.ERR_INVALID_ARGUMENT)
        self.assertIn("noise->dropout is 2", str(cm.exception))


class TestScenes(Base):
    def test_instance_gives_transformed_answer(self):
        src = self.ctx.mesh_scene(*plane_x(1.0, half=0.5))
        world = self.ctx.create_scene(max_triangles=0, max_geometries=0, max_instances=2)
        q = rangecast.quaternion_from_euler(0, 0, math.pi / 2)  # the plane now faces -y at y = 2 * scale
        a = world.add_instance(src, [0, 0, 0] + list(q), scale=3.0)
        b = world.add_instance(src, [-10, 0, 0, 0, 0, 0, 1])
        world.commit()
        self.assertEqual((a, b), (0, 1))
        dirs = np.array([[0, 1, 0], [-1, 0, 0]], np.float32)
        s = self.ctx.rays_sensor(dirs, 0.01, 100.0)
        out = self.ctx.simulate(world, s, IDENTITY, ("ranges", "inst_ids", "normals"))
        np.testing.assert_allclose(out["ranges"][0, 0], [3.0, 9.0], rtol=1e-6)
        self.assertEqual(out["inst_ids"][0, 0].tolist(), [0, 1])
        np.testing.assert_allclose(out["normals"][0, 0], [[0, -1, 0], [1, 0, 0]], atol=1e-6)
        world.set_instance_transform(1, [-5, 0, 0, 0, 0, 0, 1])
        world.commit()
        self.assertAlmostEqual(float(self.ctx.simulate(world, s, IDENTITY)["ranges"][0, 0, 1]), 4.0, places=5)

    def test_referenced_mesh_refits(self):
        v, t = plane_x(2.0)
        scene = self.ctx.mesh_scene(v, t)
        s = self.ctx.rays_sensor([[1, 0, 0]], 0.01, 100.0)
        self.assertAlmostEqual(float(self.ctx.simulate(scene, s, IDENTITY)["ranges"][0, 0, 0]), 2.0, places=5)
        scene.vertices(0)[:, 0] = 5.0
        scene.update_mesh(0)
        scene.commit()
        self.assertAlmostEqual(float(self.ctx.simulate(scene, s, IDENTITY)["ranges"][0, 0, 0]), 5.0, places=5)

    def test_padded_vertices_and_converted_inputs(self):
        v, t = plane_x(3.0)
        padded = np.concatenate([v, np.zeros((4, 1), np.float32)], axis=1)
        s = self.ctx.rays_sensor([[1, 0.2, 0.1]], 0.01, 100.0)
        want = self.ctx.simulate(self.ctx.mesh_scene(v, t), s, IDENTITY)["ranges"]
        for verts, tris in ((padded, t), (v.astype(np.float64), t.astype(np.int64)), (v.tolist(), t.tolist())):
            got = self.ctx.simulate(self.ctx.mesh_scene(verts, tris), s, IDENTITY)["ranges"]
            np.testing.assert_array_equal(got, want)

    def test_info_bounds_memory_and_progress(self):
        stages = []
        scene = self.ctx.mesh_scene(*box((-1, -2, -3), (1, 2, 3)), progress=lambda st, f: stages.append((st, f)))
        self.assertTrue(stages and stages[-1][1] == 1.0)
        np.testing.assert_array_equal(scene.bounds, [-1, -2, -3, 1, 2, 3])
        info = scene.info
        self.assertEqual((info["triangle_count"], info["geometry_count"], info["committed"]), (12, 1, True))
        m = self.ctx.memory_stats()
        self.assertGreater(m["arena_used"], info["bytes"])
        self.assertGreaterEqual(m["arena_peak"], m["arena_used"])
        self.assertGreaterEqual(m["arena_size"], m["arena_peak"])


class TestAgreement(unittest.TestCase):
    def scan(self, backend, threads, poses):
        with rangecast.Context(backend=backend, threads=threads) as ctx:
            scene = ctx.mesh_scene(*uv_sphere(20.0, 60, 120))
            lidar = ctx.preset_sensor("vlp16")
            return ctx.simulate(scene, lidar, poses, ("ranges", "prim_ids", "normals"))

    def poses(self, n=6, dtype=np.float32):
        return random_poses(n, dtype)

    def test_thread_count_independent(self):
        one, two = self.scan("bvh", 1, self.poses()), self.scan("bvh", 2, self.poses())
        for k in one:
            np.testing.assert_array_equal(one[k], two[k])

    def test_double_poses_agree_with_float(self):
        f = self.scan("bvh", 2, self.poses())["ranges"]
        d = self.scan("bvh", 2, self.poses().astype(np.float64))["ranges"]
        np.testing.assert_allclose(d, f, rtol=1e-5)

    def test_backends_agree(self):
        ref = self.scan("bvh", 2, self.poses())["ranges"]
        for backend in ("embree", "vulkan"):
            if not rangecast.backend_available(backend):
                continue
            with self.subTest(backend=backend):
                try:
                    got = self.scan(backend, 2, self.poses())["ranges"]
                except Error as e:
                    if e.status == F.ERR_UNSUPPORTED:  # built in, but no device here
                        continue
                    raise
                np.testing.assert_allclose(got, ref, rtol=1e-5)


    def test_vulkan_ray_query_agrees_or_is_refused(self):
        with self.assertRaises(Error) as cm:
            rangecast.Context("bvh", vulkan_ray_query=True)
        self.assertEqual(cm.exception.status, F.ERR_INVALID_ARGUMENT)
        self.assertIn("RC_CONTEXT_VULKAN_RAY_QUERY", str(cm.exception))
        if not rangecast.backend_available("vulkan"):
            self.skipTest("no Vulkan backend built in")
        try:
            ctx = rangecast.Context("vulkan", threads=2, vulkan_ray_query=True)
        except Error as e:
            required = os.environ.get("RC_TEST_REQUIRE_RAY_QUERY", "0") not in ("", "0")
            if required or e.status != F.ERR_UNSUPPORTED or "RC_CONTEXT_VULKAN_RAY_QUERY" not in str(e):
                raise
            self.skipTest("this device has no ray query: %s" % e)
        with ctx:
            scene = ctx.mesh_scene(*uv_sphere(20.0, 60, 120))
            got = ctx.simulate(scene, ctx.preset_sensor("vlp16"), self.poses(), ("ranges",))["ranges"]
        ref = self.scan("bvh", 2, self.poses())["ranges"]
        np.testing.assert_allclose(got, ref, rtol=1e-5)


class TestThreads(Base):
    def test_python_threads_share_a_context_one_call_at_a_time(self):
        import threading
        scene = self.ctx.mesh_scene(*uv_sphere(10.0))
        lidar = self.ctx.preset_sensor("vlp16-360")
        poses = TestAgreement().poses(4)
        want = self.ctx.simulate(scene, lidar, poses)["ranges"]
        bad = []

        def worker():
            for _ in range(20):
                if not np.array_equal(self.ctx.simulate(scene, lidar, poses)["ranges"], want):
                    bad.append(1)
        workers = [threading.Thread(target=worker) for _ in range(4)]
        for w in workers:
            w.start()
        for w in workers:
            w.join()
        self.assertEqual(bad, [])

    def test_callbacks_cannot_reenter_and_collected_objects_wait(self):
        import gc
        seen = []
        box_v, box_t = box((-1, -1, -1), (1, 1, 1))
        doomed = [self.ctx.preset_sensor("d435")]
        before = self.ctx.memory_stats()["arena_used"]

        def progress(stage, fraction):
            try:
                self.ctx.preset_sensor("vlp16")
            except Error as e:
                seen.append(e.status)
            if doomed:
                doomed.pop()  # the sensor's last reference: collected inside the C call
                gc.collect()
        self.ctx.mesh_scene(box_v, box_t, progress=progress)
        self.assertIn(F.ERR_MISUSE, seen)
        self.assertEqual(doomed, [])
        # the D435's ray table (848 x 480 directions) went back to the arena after the commit
        self.assertLess(self.ctx.memory_stats()["arena_used"], before)


class TestBadInput(StatusAssertions, Base):
    def setUp(self):
        Base.setUp(self)
        self.scene = self.ctx.mesh_scene(*plane_x(3.0))
        self.lidar = self.ctx.rays_sensor([[1, 0, 0], [0, 0, 1]], 0.1, 10.0)

    def test_bad_poses_write_nothing(self):
        out = {"ranges": np.full((2, 1, 2), 42.0, np.float32)}
        sim = self.ctx.simulate
        self.assertStatus(F.ERR_NON_FINITE, "poses[1]", sim, self.scene, self.lidar,
                          [IDENTITY, [0, 0, np.nan, 0, 0, 0, 1]], out=out)
        self.assertStatus(F.ERR_INVALID_ARGUMENT, "poses[0]", sim, self.scene, self.lidar,
                          [[0, 0, 0, 0, 0, 0, 2], IDENTITY], out=out)
        self.assertTrue((out["ranges"] == 42.0).all(), "a failed call wrote results")
        self.assertStatus(F.ERR_INVALID_ARGUMENT, "poses must be", sim, self.scene, self.lidar, [1, 2, 3])
        self.assertStatus(F.ERR_INVALID_ARGUMENT, "out['ranges']", sim, self.scene, self.lidar, IDENTITY,
                          out={"ranges": np.zeros((1, 2, 1), np.float32)})
        self.assertStatus(F.ERR_INVALID_ARGUMENT, "attribute 'depth'", sim, self.scene, self.lidar, IDENTITY,
                          ("depth",))
        self.assertStatus(F.ERR_INVALID_ARGUMENT, "attributes is empty", sim, self.scene, self.lidar, IDENTITY, ())

    def test_out_buffers_are_written_in_place(self):
        out = {"ranges": np.zeros((1, 1, 2), np.float32)}
        got = self.ctx.simulate(self.scene, self.lidar, IDENTITY, out=out)
        self.assertIs(got["ranges"], out["ranges"])
        self.assertAlmostEqual(float(out["ranges"][0, 0, 0]), 3.0, places=5)

    def test_bad_meshes(self):
        v, t = plane_x(1.0)
        self.assertStatus(F.ERR_OUT_OF_RANGE, "", self.ctx.mesh_scene, v, t + 2)
        self.assertStatus(F.ERR_OUT_OF_RANGE, "0 .. 2^32-1", self.ctx.mesh_scene, v, t.astype(np.int64) - 1)
        bad = v.copy()
        bad[2, 1] = np.inf
        self.assertStatus(F.ERR_NON_FINITE, "", self.ctx.mesh_scene, bad, t)
        self.assertStatus(F.ERR_INVALID_ARGUMENT, "triangles must be (T, 3)", self.ctx.mesh_scene, v,
                          np.zeros((0, 3), np.uint32))
        self.assertStatus(F.ERR_INVALID_ARGUMENT, "vertices must be", self.ctx.mesh_scene, v[:, :2], t)
        self.assertStatus(F.ERR_INVALID_ARGUMENT, "triangles must be integers", self.ctx.mesh_scene, v,
                          t.astype(np.float32))

    def test_misuse_and_handles(self):
        fresh = self.ctx.create_scene(max_triangles=2)
        fresh.add_mesh(*plane_x(1.0))
        self.assertStatus(F.ERR_NOT_COMMITTED, "", self.ctx.simulate, fresh, self.lidar, IDENTITY)
        self.assertStatus(F.ERR_INVALID_ARGUMENT, "no sensor preset named 'hdl64'", self.ctx.preset_sensor, "hdl64")
        self.assertStatus(F.ERR_INVALID_ARGUMENT, "backend 'optix'", rangecast.Context, backend="optix")
        # a failed create's message comes from the library's log line
        self.assertStatus(F.ERR_INVALID_ARGUMENT, "desc->thread_count is 100000", rangecast.Context, threads=100000)
        self.assertStatus(F.ERR_INVALID_ARGUMENT, "range", self.ctx.spherical_sensor, (0, 0.1, 3), (0, 0.1, 1),
                          5.0, 1.0)
        self.assertStatus(F.ERR_NON_FINITE, "", self.ctx.rays_sensor, [[np.nan, 0, 1]], 0.1, 10.0)
        with rangecast.Context(backend="bvh", threads=1) as other:
            self.assertStatus(F.ERR_INVALID_ARGUMENT, "Scene of this context", other.simulate, self.scene,
                              self.lidar, IDENTITY)
        self.lidar.close()
        self.assertStatus(F.ERR_INVALID_HANDLE, "Sensor is closed", self.ctx.simulate, self.scene, self.lidar,
                          IDENTITY)
        self.ctx.close()
        self.assertStatus(F.ERR_INVALID_HANDLE, "context is closed", self.ctx.preset_sensor, "vlp16")
        self.assertStatus(F.ERR_INVALID_HANDLE, "Scene is closed", lambda: self.scene.bounds)

    def test_arena_too_small_and_log(self):
        lines = []
        with rangecast.Context(backend="bvh", threads=1, arena_bytes=64 << 10,
                               log=lambda level, msg: lines.append((level, msg))) as small:
            v, t = uv_sphere(5.0, 60, 120)
            e = self.assertStatus(F.ERR_OUT_OF_MEMORY, "", small.mesh_scene, v, t, copy=True)
        self.assertTrue(any(level == 1 and msg in str(e) for level, msg in lines), lines)


if __name__ == "__main__":
    unittest.main()
