"""rangecast.ouster: rays from Ouster metadata. Known rays of a made-up
sensor (the lidar-to-sensor turn, the beam origins, the clockwise encoder),
both metadata layouts giving the same rays, and a scan of a closed box whose
every range is checked against the box's walls computed in float64 from the
same rays, with points where the sensor would put them and sensor_ranges
adding the beam offset."""

import json
import math
import os
import sys
import tempfile
import unittest

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
import rangecast  # noqa: E402
from rangecast import ouster  # noqa: E402
from test_rangecast import box  # noqa: E402

# four beams, eight columns; an OS1-like beam offset and the default turn
NESTED = {
    "beam_intrinsics": {
        "beam_altitude_angles": [15.0, 5.0, -5.0, -15.0],
        "beam_azimuth_angles": [3.0, -1.0, 1.0, -3.0],
        "lidar_origin_to_beam_origin_mm": 15.806,
        "beam_to_lidar_transform": [1, 0, 0, 15.806, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1],
    },
    "lidar_intrinsics": {"lidar_to_sensor_transform": [-1, 0, 0, 0, 0, -1, 0, 0, 0, 0, 1, 36.18, 0, 0, 0, 1]},
    "lidar_data_format": {"columns_per_frame": 8, "pixels_per_column": 4},
    "config_params": {"lidar_mode": "8x10"},
    "sensor_info": {"prod_line": "OS-1-4"},
}
LEGACY = {
    "beam_altitude_angles": [15.0, 5.0, -5.0, -15.0],
    "beam_azimuth_angles": [3.0, -1.0, 1.0, -3.0],
    "lidar_origin_to_beam_origin_mm": 15.806,
    "lidar_to_sensor_transform": [-1, 0, 0, 0, 0, -1, 0, 0, 0, 0, 1, 36.18, 0, 0, 0, 1],
    "lidar_mode": "8x10",
    "prod_line": "OS-1-4",
}


def box_distance(o, d, lo, hi):
    """Distance from o (inside the box) along unit d to the box's walls, float64."""
    t = np.inf
    for k in range(3):
        if d[k] > 0:
            t = min(t, (hi[k] - o[k]) / d[k])
        elif d[k] < 0:
            t = min(t, (lo[k] - o[k]) / d[k])
    return t


class OusterRays(unittest.TestCase):
    def test_known_rays(self):
        meta = ouster.read_metadata(NESTED)
        origins, dirs = ouster.rays(meta)
        self.assertEqual(origins.shape, (32, 3))
        # beam 1 (altitude 5, azimuth -1), column 0: encoder 2 pi, so in the
        # lidar frame the ray turns +1 degree from +x; the sensor frame is
        # that turned 180 degrees about z
        a, p = math.radians(1.0), math.radians(5.0)
        want = np.array([-math.cos(a) * math.cos(p), -math.sin(a) * math.cos(p), math.sin(p)])
        np.testing.assert_allclose(dirs[1 * 8 + 0], want, atol=1e-7)
        # its beam origin: 15.806 mm along lidar +x, i.e. sensor -x, 36.18 mm up
        np.testing.assert_allclose(origins[8], [-0.015806, 0.0, 0.03618], atol=1e-8)
        # column 2 of 8: encoder 2 pi (1 - 2/8) = 270 degrees, clockwise from above
        te = 2 * math.pi * 0.75
        np.testing.assert_allclose(origins[2], [-0.015806 * math.cos(te), -0.015806 * math.sin(te), 0.03618],
                                   atol=1e-8)
        np.testing.assert_allclose(np.linalg.norm(dirs.astype(np.float64), axis=1), 1.0, atol=1e-6)

    def test_layouts_agree(self):
        a = ouster.rays(ouster.read_metadata(NESTED))
        b = ouster.rays(ouster.read_metadata(LEGACY))
        c = ouster.rays(ouster.read_metadata(json.dumps(LEGACY)))
        for x, y, z in zip(a, b, c):
            np.testing.assert_array_equal(x, y)
            np.testing.assert_array_equal(x, z)

    def test_bad_metadata(self):
        with self.assertRaises(rangecast.Error):  # a mirror is not a rigid transform
            ouster.rays(ouster.read_metadata(dict(LEGACY, lidar_to_sensor_transform=[1, 0, 0, 0, 0, 1, 0, 0,
                                                                                     0, 0, -1, 0, 0, 0, 0, 1])))
        for broken, words in (({"lidar_mode": "1024x10"}, "beam_altitude_angles"),
                              (dict(LEGACY, beam_azimuth_angles=[0.0]), "same length"),
                              (dict(LEGACY, lidar_mode="unknown"), "columns_per_frame"),
                              (dict(LEGACY, lidar_to_sensor_transform=[1, 0, 0]), "16 finite"),
                              (dict(LEGACY, pixel_shift_by_row=[1, 2]), "one integer a beam"),
                              (dict(LEGACY, pixel_shift_by_row=[1, 2, 3.5, 4]), "one integer a beam"),
                              (dict(LEGACY, column_window=[0, 8]), "column_window"),
                              (dict(LEGACY, column_window=[3]), "column_window")):
            with self.assertRaises(ValueError) as e:
                ouster.read_metadata(broken)
            self.assertIn(words, str(e.exception))

    def test_box_scan(self):
        lo, hi = np.array([-3.0, -2.0, -1.5]), np.array([4.0, 5.0, 2.5])
        meta = dict(NESTED, lidar_data_format={"columns_per_frame": 64, "pixels_per_column": 4},
                    config_params={"lidar_mode": "64x10"})
        with tempfile.TemporaryDirectory() as tmp, rangecast.Context(backend="bvh", threads=2) as ctx:
            path = os.path.join(tmp, "meta.json")
            with open(path, "w") as f:
                json.dump(meta, f)
            v, t = box(lo, hi)
            scene = ctx.mesh_scene(v, t)
            lidar = ouster.sensor(ctx, path, range_min=0.05, range_max=50.0)
            scan = ctx.simulate(scene, lidar, [0, 0, 0, 0, 0, 0, 1], ("ranges", "points"))
            ranges, points = scan["ranges"][0], scan["points"][0]
            self.assertEqual(ranges.shape, (4, 64))
            origins, dirs = ouster.rays(ouster.read_metadata(path))
            origins, dirs = origins.astype(np.float64), dirs.astype(np.float64)
            for k in range(4 * 64):
                want = box_distance(origins[k], dirs[k], lo, hi)
                got = ranges.reshape(-1)[k]
                self.assertLess(abs(got - want), 2e-5 * want, "ray %d: %r against %r" % (k, got, want))
                np.testing.assert_allclose(points.reshape(-1, 3)[k], origins[k] + want * dirs[k], atol=5e-5)
            reported = ouster.sensor_ranges(ranges, path)
            np.testing.assert_allclose(reported - ranges, 0.015806, atol=1e-6)


    def test_frame_window_and_destagger(self):
        meta = ouster.read_metadata(dict(NESTED, lidar_data_format={
            "columns_per_frame": 8, "pixels_per_column": 4, "column_window": [6, 1],
            "pixel_shift_by_row": [2, 0, -1, 9]}))
        self.assertEqual(meta["column_window"], (6, 1))
        np.testing.assert_array_equal(ouster.window_mask(meta), [True, True, False, False, False, False, True, True])
        field = np.arange(2 * 4 * 8, dtype=np.float32).reshape(2, 4, 8)
        out = ouster.destagger(field, meta)
        for u, s in enumerate((2, 0, -1, 9)):
            for v in range(8):  # out[u][(v + shift) mod 8] = in[u][v], as the SDK
                self.assertEqual(out[1, u, (v + s) % 8], field[1, u, v])
        r = ouster.sensor_ranges(np.full((4, 8), 10.0), meta)
        self.assertTrue(np.all(np.isnan(r[:, 2:6])))
        np.testing.assert_allclose(r[:, [0, 1, 6, 7]], 10.015806, atol=1e-9)
        whole = ouster.read_metadata(NESTED)  # no window, no shifts
        self.assertTrue(np.all(ouster.window_mask(whole)))
        self.assertIsNone(whole["pixel_shift"])
        with self.assertRaises(ValueError):
            ouster.destagger(field, whole)
        with self.assertRaises(ValueError):
            ouster.destagger(field[:, :3], meta)


if __name__ == "__main__":
    unittest.main()
