"""Ouster lidars from their metadata: the JSON an Ouster sensor (and its SDK)
writes, turned into a rays sensor whose every ray leaves its own beam origin.

    meta = rangecast.ouster.read_metadata("os1-64.json")
    lidar = rangecast.ouster.sensor(ctx, meta)           # rows = beams, columns = measurement ids
    scan = ctx.simulate(scene, lidar, pose, ("ranges", "points"))
    r = rangecast.ouster.sensor_ranges(scan["ranges"], meta)   # what the sensor would report
    image = rangecast.ouster.destagger(r, meta)                # as Ouster's SDK shows a frame

The rays come from the C library's rc_ouster_rays (include/rangecast/rangecast.h),
which follows the geometry Ouster documents for turning a range image into
points ("lidar range data to sensor XYZ"), per beam u and measurement id v of a
frame of W columns:

    encoder   te = 2 pi (1 - v / W)          (the rotor turns clockwise seen from above)
    azimuth   ta = -beam_azimuth_angles[u]   (degrees -> radians)
    altitude  p  =  beam_altitude_angles[u]
    direction    = (cos(te + ta) cos p, sin(te + ta) cos p, sin p)          (lidar frame)
    beam origin  = (bx cos te, bx sin te, bz)   bx, bz: beam_to_lidar_transform's
                   x and z translation (lidar_origin_to_beam_origin_mm, 0 on older metadata)

and both go through lidar_to_sensor_transform into the sensor frame (mm to m).
The library traces each ray from its beam origin, so points come out exactly
where the sensor would put them. The sensor reports its range from the lidar
axis, not from the beam origin: sensor_ranges adds the beam offset
sqrt(bx^2 + bz^2) back. Rmagine's Ouster loader drops the beam origin; at
15.8 mm on an OS1 that moves every point by that much.

Both metadata layouts are read: the current nested one (beam_intrinsics,
lidar_intrinsics, lidar_data_format, config_params, sensor_info) and the flat
legacy one (beam_altitude_angles ... at the top level). The metadata carries no
range limits: pass range_min and range_max, or take the OS1 defaults here.
"""

import ctypes
import json
import math

import numpy as np

from . import _ffi as F
from ._api import Error

__all__ = ["read_metadata", "rays", "sensor", "sensor_ranges", "window_mask", "destagger"]

# Ouster's default lidar-to-sensor transform (the lidar frame turned 180
# degrees about z, 36.18 mm up), for metadata that does not carry one.
_DEFAULT_LIDAR_TO_SENSOR = [-1, 0, 0, 0, 0, -1, 0, 0, 0, 0, 1, 36.18, 0, 0, 0, 1]


def _matrix(values, what):
    m = np.asarray(values, dtype=np.float64)
    if m.size != 16 or not np.all(np.isfinite(m)):
        raise ValueError("ouster metadata: %s must hold 16 finite numbers (a 4x4 matrix, row by row)" % what)
    return m.reshape(4, 4)


def read_metadata(source):
    """The parts of Ouster metadata that place the rays, from a path, a JSON
    string or an already parsed dict: a dict with altitudes and azimuths
    (degrees, one per beam), columns (measurement ids a frame), beam_to_lidar
    and lidar_to_sensor (4x4, mm), prod_line, pixel_shift (one int a beam,
    from pixel_shift_by_row; None when absent) and column_window ((start,
    end) inclusive, the whole frame when absent). ValueError names what is
    missing or malformed."""
    if isinstance(source, dict):
        raw = source
    elif isinstance(source, str) and source.lstrip().startswith("{"):
        raw = json.loads(source)
    else:
        with open(source, "r") as f:
            raw = json.load(f)
    beams = raw.get("beam_intrinsics", raw)
    lidar = raw.get("lidar_intrinsics", raw)
    fmt = raw.get("lidar_data_format", raw.get("data_format", {}))
    config = raw.get("config_params", raw)
    info = raw.get("sensor_info", raw)
    try:
        altitudes = np.asarray(beams["beam_altitude_angles"], dtype=np.float64)
        azimuths = np.asarray(beams["beam_azimuth_angles"], dtype=np.float64)
    except KeyError as e:
        raise ValueError("ouster metadata: no %s (neither under beam_intrinsics nor at the top level)" % e)
    if altitudes.ndim != 1 or altitudes.shape != azimuths.shape or altitudes.size == 0:
        raise ValueError("ouster metadata: beam_altitude_angles and beam_azimuth_angles must be two lists of "
                         "the same length (one angle per beam), got %d and %d" % (altitudes.size, azimuths.size))
    if not (np.all(np.isfinite(altitudes)) and np.all(np.isfinite(azimuths))):
        raise ValueError("ouster metadata: a beam angle is not finite")
    columns = fmt.get("columns_per_frame")
    if columns is None:
        mode = str(config.get("lidar_mode", ""))
        columns = int(mode.split("x")[0]) if "x" in mode and mode.split("x")[0].isdigit() else None
    if columns is None or int(columns) <= 0:
        raise ValueError("ouster metadata: no columns_per_frame and no lidar_mode like '1024x10'")
    rows = fmt.get("pixels_per_column", altitudes.size)
    if int(rows) != altitudes.size:
        raise ValueError("ouster metadata: pixels_per_column is %s but %d beam angles are given"
                         % (rows, altitudes.size))
    if "beam_to_lidar_transform" in beams:
        beam_to_lidar = _matrix(beams["beam_to_lidar_transform"], "beam_to_lidar_transform")
    else:
        beam_to_lidar = np.identity(4)
        beam_to_lidar[0, 3] = float(beams.get("lidar_origin_to_beam_origin_mm", 0.0))
    lidar_to_sensor = _matrix(lidar.get("lidar_to_sensor_transform", _DEFAULT_LIDAR_TO_SENSOR),
                              "lidar_to_sensor_transform")
    columns = int(columns)
    shift = fmt.get("pixel_shift_by_row", raw.get("pixel_shift_by_row"))
    if shift is not None:
        shift = np.asarray(shift)
        if shift.shape != altitudes.shape or not np.all(np.equal(np.mod(shift, 1), 0)):
            raise ValueError("ouster metadata: pixel_shift_by_row must be one integer a beam (%d), got %r"
                             % (altitudes.size, fmt.get("pixel_shift_by_row")))
        shift = shift.astype(np.int64)
    window = fmt.get("column_window", raw.get("column_window", [0, columns - 1]))
    if (len(window) != 2 or any(int(c) != c or c < 0 or c >= columns for c in window)):
        raise ValueError("ouster metadata: column_window must be two column indices [start, end] below "
                         "columns_per_frame (%d), got %r" % (columns, window))
    return {"altitudes": altitudes, "azimuths": azimuths, "columns": columns,
            "beam_to_lidar": beam_to_lidar, "lidar_to_sensor": lidar_to_sensor,
            "prod_line": str(info.get("prod_line", "")), "pixel_shift": shift,
            "column_window": (int(window[0]), int(window[1]))}


def _c_rays(meta):
    """rc_ouster_rays on meta: (origins, directions) as (N, 3) float32."""
    h, w = meta["altitudes"].size, meta["columns"]
    alt = np.ascontiguousarray(meta["altitudes"], dtype=np.float64)
    azi = np.ascontiguousarray(meta["azimuths"], dtype=np.float64)
    d = F.lib.rc_ouster_desc_default()
    d.beams, d.columns = h, w
    d.altitudes_deg = alt.ctypes.data_as(ctypes.POINTER(ctypes.c_double))
    d.azimuths_deg = azi.ctypes.data_as(ctypes.POINTER(ctypes.c_double))
    d.beam_to_lidar[:] = [float(x) for x in meta["beam_to_lidar"].reshape(16)]
    d.lidar_to_sensor[:] = [float(x) for x in meta["lidar_to_sensor"].reshape(16)]
    origins = np.empty((h * w, 3), np.float32)
    directions = np.empty((h * w, 3), np.float32)
    status = F.lib.rc_ouster_rays(ctypes.byref(d), None, origins.ctypes.data_as(ctypes.POINTER(ctypes.c_float)),
                                  directions.ctypes.data_as(ctypes.POINTER(ctypes.c_float)), None)
    if status != 0:
        raise Error(status, "rc_ouster_rays refused the metadata (%d beams x %d columns): a transform that is not "
                    "rigid, or more than 2^24 rays" % (h, w))
    return origins, directions


def _meta(meta):
    return meta if isinstance(meta, dict) and "altitudes" in meta else read_metadata(meta)


def rays(meta):
    """(origins, directions): two (beams * columns, 3) float32 arrays in the
    sensor frame, metres and unit vectors, row = beam, column = measurement
    id (rc_ouster_rays). meta: read_metadata's dict, or what it reads."""
    return _c_rays(_meta(meta))


def sensor(ctx, meta, range_min=0.3, range_max=120.0, mounting=None):
    """A rays sensor of ctx shaped (beams, columns): ctx.simulate returns
    (poses, beams, columns) arrays in the sensor's own layout (measurement id
    order, not destaggered). meta: read_metadata's dict, or what it reads.
    range_min and range_max bound the distance from each beam origin; the
    defaults are an OS1's."""
    meta = _meta(meta)
    origins, directions = _c_rays(meta)
    return ctx.rays_sensor(directions, range_min, range_max, origins=origins,
                           shape=(meta["altitudes"].size, meta["columns"]), mounting=mounting)


def window_mask(meta):
    """Which measurement ids the frame measures: a bool array of columns,
    True inside column_window [start, end] (inclusive; it wraps past the last
    column when start > end)."""
    meta = _meta(meta)
    start, end = meta["column_window"]
    v = np.arange(meta["columns"])
    return (v >= start) & (v <= end) if start <= end else (v >= start) | (v <= end)


def sensor_ranges(ranges, meta):
    """Ranges as the sensor reports them: the simulated distance from each beam
    origin plus the beam offset (no return stays +inf, too near stays -inf),
    and NaN in the columns outside the frame's column_window (no data there).
    ranges: (..., beams, columns), as ctx.simulate returns them for sensor()."""
    meta = _meta(meta)
    b = meta["beam_to_lidar"]
    offset = math.hypot(b[0, 3], b[2, 3]) / 1000.0  # rc_ouster_rays' beam_offset_m, without making every ray
    r = np.array(ranges, dtype=np.float64, copy=True)
    finite = np.isfinite(r)
    r[finite] += offset
    if r.ndim >= 2 and r.shape[-1] == meta["columns"]:
        r[..., ~window_mask(meta)] = np.nan
    return r


def destagger(field, meta):
    """A field of a frame (..., beams, columns) in the sensor's measurement-id
    order turned into an image whose columns share one azimuth, as Ouster's
    SDK destaggers: out[..., u, (v + pixel_shift[u]) mod columns] = in[..., u, v].
    ValueError when the metadata has no pixel_shift_by_row."""
    meta = _meta(meta)
    shift = meta["pixel_shift"]
    if shift is None:
        raise ValueError("ouster metadata: no pixel_shift_by_row to destagger with")
    f = np.asarray(field)
    if f.ndim < 2 or f.shape[-2:] != (shift.size, meta["columns"]):
        raise ValueError("destagger: expected (..., %d, %d), got %s" % (shift.size, meta["columns"], f.shape))
    out = np.empty_like(f)
    for u in range(shift.size):
        out[..., u, :] = np.roll(f[..., u, :], int(shift[u]), axis=-1)
    return out
