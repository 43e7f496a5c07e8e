/* Presets of common sensors, filled into the public descriptors. Angles are
 * worked out in double from the datasheet figures and stored as float
 * radians. No context: statuses only, no messages. */
#include "sensor/sensor.h"

#include <math.h>
#include <string.h>

#define SENSOR_PI 3.14159265358979323846
#define DEG(x) ((x) * (SENSOR_PI / 180.0))

#define MID40_RAYS 10000u
#define MID40_FOV_DEG 38.4

typedef struct preset_entry {
    uint32_t id;
    uint32_t model;
    const char *name;
} preset_entry;

static const preset_entry k_presets[] = {
    {RC_PRESET_VELODYNE_VLP16, RC_SENSOR_SPHERICAL, "vlp16"},
    {RC_PRESET_VELODYNE_VLP16_360, RC_SENSOR_SPHERICAL, "vlp16-360"},
    {RC_PRESET_OUSTER_OS1_64, RC_SENSOR_SPHERICAL, "os1-64"},
    {RC_PRESET_REALSENSE_D435, RC_SENSOR_PINHOLE, "d435"},
    {RC_PRESET_LIVOX_MID40, RC_SENSOR_O1DN, "livox-mid40"},
    {RC_PRESET_HOKUYO_UST10LX, RC_SENSOR_SPHERICAL, "ust-10lx"},
    {RC_PRESET_ROBOTIS_LDS01, RC_SENSOR_SPHERICAL, "lds-01"},
};
#define PRESET_COUNT (sizeof k_presets / sizeof k_presets[0])

static const preset_entry *find_preset(uint32_t id)
{
    size_t i;
    for (i = 0; i < PRESET_COUNT; ++i)
        if (k_presets[i].id == id) return &k_presets[i];
    return NULL;
}

/* ASCII, case-insensitive: "VLP16" finds "vlp16". */
static int name_equal(const char *a, const char *b)
{
    for (;; ++a, ++b) {
        char ca = *a, cb = *b;
        if (ca >= 'A' && ca <= 'Z') ca = (char)(ca - 'A' + 'a');
        if (cb >= 'A' && cb <= 'Z') cb = (char)(cb - 'A' + 'a');
        if (ca != cb) return 0;
        if (ca == '\0') return 1;
    }
}

uint32_t rc_preset_from_name(const char *name)
{
    size_t i;
    if (!name) return 0;
    for (i = 0; i < PRESET_COUNT; ++i)
        if (name_equal(name, k_presets[i].name)) return k_presets[i].id;
    return 0;
}

uint32_t rc_preset_model(uint32_t preset)
{
    const preset_entry *e = find_preset(preset);
    return e ? e->model : 0;
}

static void set_axis(rc_angle_axis *axis, double min_rad, double inc_rad, uint32_t count)
{
    axis->min = (float)min_rad;
    axis->increment = (float)inc_rad;
    axis->count = count;
}

rc_status rc_preset_spherical(uint32_t preset, rc_spherical_desc *desc)
{
    rc_spherical_desc d;
    if (!desc || rc_preset_model(preset) != RC_SENSOR_SPHERICAL) return RC_ERR_INVALID_ARGUMENT;
    d = rc_spherical_desc_default();
    switch (preset) {
    case RC_PRESET_VELODYNE_VLP16:
    case RC_PRESET_VELODYNE_VLP16_360:
        /* 16 lasers, -15..+15 deg in 2 deg steps; 900 columns of 0.4 deg
         * (600 rpm at 10 Hz) or the coarser 360 x 1 deg used by Rmagine. */
        set_axis(&d.phi, DEG(-15.0), DEG(2.0), 16);
        if (preset == RC_PRESET_VELODYNE_VLP16)
            set_axis(&d.theta, DEG(-180.0), DEG(0.4), 900);
        else
            set_axis(&d.theta, DEG(-180.0), DEG(1.0), 360);
        d.common.range_min = 0.5f;
        d.common.range_max = 130.0f;
        break;
    case RC_PRESET_OUSTER_OS1_64:
        /* 64 beams evenly over a 45 deg vertical field centred on the horizon,
         * 1024 columns over 360 deg. Real units ship a per-beam altitude and
         * azimuth table and a beam-origin offset from the sensor frame (about
         * 15 mm); this preset ignores both. For exact rays, read the unit's
         * metadata and build an OnDn sensor. */
        set_axis(&d.phi, DEG(-22.5), DEG(45.0 / 63.0), 64);
        set_axis(&d.theta, DEG(-180.0), DEG(360.0 / 1024.0), 1024);
        d.common.range_min = 0.3f;
        d.common.range_max = 120.0f;
        break;
    case RC_PRESET_HOKUYO_UST10LX:
        /* 270 deg in 0.25 deg steps, as urg_node publishes it (angle_min
         * -135 deg, 1081 ranges); the datasheet's guaranteed 0.06..10 m */
        set_axis(&d.phi, 0.0, 0.0, 1);
        set_axis(&d.theta, DEG(-135.0), DEG(0.25), 1081);
        d.common.range_min = 0.06f;
        d.common.range_max = 10.0f;
        break;
    case RC_PRESET_ROBOTIS_LDS01:
        /* TurtleBot3's 360 deg scanner: 360 ranges from angle 0 in 1 deg
         * steps, 0.12..3.5 m, as its ROS driver publishes them */
        set_axis(&d.phi, 0.0, 0.0, 1);
        set_axis(&d.theta, 0.0, DEG(1.0), 360);
        d.common.range_min = 0.12f;
        d.common.range_max = 3.5f;
        break;
    default:
        return RC_ERR_INVALID_ARGUMENT;
    }
    *desc = d;
    return RC_OK;
}

rc_status rc_preset_pinhole(uint32_t preset, rc_pinhole_desc *desc)
{
    rc_pinhole_desc d;
    if (!desc || rc_preset_model(preset) != RC_SENSOR_PINHOLE) return RC_ERR_INVALID_ARGUMENT;
    d = rc_pinhole_desc_default();
    switch (preset) {
    case RC_PRESET_REALSENSE_D435:
        /* Depth stream 848 x 480 with the datasheet's 87 x 58 deg field of
         * view: fx = (w/2) / tan(hfov/2), fy = (h/2) / tan(vfov/2). The
         * principal point is the image centre (424, 240); as the header
         * specifies, pixel u looks along u - cx with no half-pixel offset, so
         * column 424 is the optical axis. */
        d.frame = RC_PINHOLE_FRAME_BODY;
        d.width = 848;
        d.height = 480;
        d.fx = (float)(424.0 / tan(DEG(87.0 / 2.0)));
        d.fy = (float)(240.0 / tan(DEG(58.0 / 2.0)));
        d.cx = 424.0f;
        d.cy = 240.0f;
        d.common.range_min = 0.1f;
        d.common.range_max = 10.0f;
        break;
    default:
        return RC_ERR_INVALID_ARGUMENT;
    }
    *desc = d;
    return RC_OK;
}

/* directions != NULL: *count is the capacity of directions in rays on entry
 * (RC_ERR_CAPACITY when smaller than the preset's, nothing written); on return
 * it is the preset's ray count. desc may be NULL; when given it is filled and
 * its directions point at the caller's array (NULL when none was given). */
rc_status rc_preset_rays(uint32_t preset, rc_rays_desc *desc, float *directions, uint32_t *count)
{
    const uint32_t model = rc_preset_model(preset);
    rc_rays_desc d;
    uint32_t n;
    float fov;
    if (!count || (model != RC_SENSOR_O1DN && model != RC_SENSOR_ONDN)) return RC_ERR_INVALID_ARGUMENT;
    d = rc_rays_desc_default();
    switch (preset) {
    case RC_PRESET_LIVOX_MID40:
        /* 38.4 deg circular field, one 10,000-ray frame (0.1 s at 100 kHz). */
        n = MID40_RAYS;
        fov = (float)DEG(MID40_FOV_DEG);
        d.common.range_min = 0.1f;
        d.common.range_max = 260.0f;
        break;
    default:
        return RC_ERR_INVALID_ARGUMENT;
    }
    if (directions && *count < n) return RC_ERR_CAPACITY;
    if (directions) rc__sensor_fill_rosette(fov, n, directions);
    if (desc) {
        d.directions = directions;
        d.origins = NULL;
        d.ray_count = n;
        d.width = 0; /* not a grid: one row of ray_count */
        d.height = 0;
        *desc = d;
    }
    *count = n;
    return RC_OK;
}
