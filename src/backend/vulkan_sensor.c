/* Per-sensor ray tables on the device, uploaded once and cached.
 *
 * Grid sensors (spherical, pinhole, cylindrical) upload two small per-axis
 * tables computed in double from the model's parameters, 2 values per column
 * then 2 per row, as floats and again as doubles (little-endian word pairs);
 * the kernel builds each ray from its row and column entries (raycast.comp,
 * sensor_ray), in double where the device has float64, exactly as
 * sensor_rays.c does:
 *   spherical    column (cos theta, sin theta), row (cos phi, sin phi)
 *   pinhole      column ((u - cx) / fx, 0),     row ((v - cy) / fy, 0)
 *   cylindrical  column (cos theta, sin theta), row ((cy - v) / fy, 0)
 * O1Dn uploads its direction table, OnDn directions then origins.
 *
 * The cache is keyed by the sensor's address and a hash of what would be
 * uploaded (the grid parameters, or the whole table), so a sensor destroyed
 * and another created at the same arena address is never served stale rays.
 * (A sensor-release hook in the backend table would let entries go at
 * rc_sensor_destroy; until then they go by least recent use.) */
#include "backend/vulkan_internal.h"

#include <math.h>
#include <string.h>

static uint64_t hash_words(uint64_t h, const void *data, size_t bytes)
{
    const unsigned char *p = (const unsigned char *)data;
    size_t i;
    for (i = 0; i + 4 <= bytes; i += 4) {
        uint32_t w;
        memcpy(&w, p + i, 4);
        h = (h ^ w) * 0x100000001B3ull;
        h ^= h >> 29;
    }
    for (; i < bytes; ++i) h = (h ^ p[i]) * 0x100000001B3ull;
    return h;
}

static uint32_t model_of(const rc_sensor *s)
{
    switch (s->model) {
    case RC_SENSOR_SPHERICAL: return RC__VK_MODEL_SPHERICAL;
    case RC_SENSOR_PINHOLE:
        return s->pinhole_frame == RC_PINHOLE_FRAME_OPTICAL ? RC__VK_MODEL_PINHOLE_OPT : RC__VK_MODEL_PINHOLE;
    case RC_SENSOR_CYLINDRICAL: return RC__VK_MODEL_CYLINDRICAL;
    case RC_SENSOR_ONDN: return RC__VK_MODEL_ONDN;
    default: return RC__VK_MODEL_O1DN;
    }
}

static int is_grid(uint32_t model) { return model >= RC__VK_MODEL_SPHERICAL; }

static uint64_t sensor_hash(const rc_sensor *s, uint32_t model)
{
    uint64_t h = 0xCBF29CE484222325ull;
    h = hash_words(h, &model, sizeof model);
    h = hash_words(h, &s->rays, sizeof s->rays);
    h = hash_words(h, &s->columns, sizeof s->columns);
    switch (model) {
    case RC__VK_MODEL_SPHERICAL: return hash_words(h, &s->spherical, sizeof s->spherical);
    case RC__VK_MODEL_PINHOLE:
    case RC__VK_MODEL_PINHOLE_OPT: return hash_words(h, &s->pinhole, sizeof s->pinhole);
    case RC__VK_MODEL_CYLINDRICAL: return hash_words(h, &s->cylindrical, sizeof s->cylindrical);
    default:
        h = hash_words(h, s->directions, (size_t)s->rays * 12u);
        if (s->origins) h = hash_words(h, s->origins, (size_t)s->rays * 12u);
        return h;
    }
}

static double axis_value(const rc_angle_axis *axis, uint32_t k)
{
    return (double)axis->min + (double)k * (double)axis->increment;
}

/* Per-axis values of a grid model, in double as sensor_rays.c computes them:
 * entry k < cols is column k, entry cols + k is row k. */
static void axis_entry(const rc_sensor *s, uint32_t model, uint32_t k, double v[2])
{
    const uint32_t cols = s->columns;
    const int row = k >= cols;
    const uint32_t i = row ? k - cols : k;
    v[1] = 0.0;
    switch (model) {
    case RC__VK_MODEL_SPHERICAL: {
        const double a = row ? axis_value(&s->spherical.phi, i) : axis_value(&s->spherical.theta, i);
        v[0] = cos(a);
        v[1] = sin(a);
        break;
    }
    case RC__VK_MODEL_PINHOLE:
    case RC__VK_MODEL_PINHOLE_OPT:
        v[0] = row ? ((double)i - (double)s->pinhole.cy) / (double)s->pinhole.fy
                   : ((double)i - (double)s->pinhole.cx) / (double)s->pinhole.fx;
        break;
    default: /* cylindrical */
        if (row) {
            v[0] = ((double)s->cylindrical.cy - (double)i) / (double)s->cylindrical.fy;
        } else {
            const double a = axis_value(&s->cylindrical.theta, i);
            v[0] = cos(a);
            v[1] = sin(a);
        }
        break;
    }
}

/* Grid: (cols + rows) entries of 2 floats, then the same entries as 2
 * doubles each (the float64 kernel uses those). Rays: the table(s). */
static uint64_t table_bytes(const rc_sensor *s, uint32_t model)
{
    if (is_grid(model)) return ((uint64_t)s->columns + s->rows) * 24u;
    return (uint64_t)s->rays * (model == RC__VK_MODEL_ONDN ? 24u : 12u);
}

static void fill_table(const rc_sensor *s, uint32_t model, unsigned char *t)
{
    if (is_grid(model)) {
        const uint32_t n = s->columns + s->rows;
        uint32_t k;
        for (k = 0; k < n; ++k) {
            double v[2];
            float f[2];
            axis_entry(s, model, k, v);
            f[0] = (float)v[0];
            f[1] = (float)v[1];
            memcpy(t + 8u * (size_t)k, f, 8);
            memcpy(t + 8u * (size_t)n + 16u * (size_t)k, v, 16);
        }
        return;
    }
    memcpy(t, s->directions, (size_t)s->rays * 12u);
    if (s->origins) memcpy(t + (size_t)s->rays * 12u, s->origins, (size_t)s->rays * 12u);
}

rc_status rc__vk_sensor_table(rc__vk_state *st, const rc_sensor *sensor, rc__vk_sensor_slot **out)
{
    const uint32_t model = model_of(sensor);
    const uint64_t hash = sensor_hash(sensor, model);
    const uint64_t bytes = table_bytes(sensor, model);
    rc__vk_sensor_slot *slot = NULL;
    uint32_t i;
    ++st->clock;
    for (i = 0; i < RC__VK_SENSOR_SLOTS; ++i) {
        rc__vk_sensor_slot *e = &st->sensors[i];
        if (e->sensor == sensor && e->model == model && e->rays == sensor->rays && e->hash == hash &&
            e->table.buf != VK_NULL_HANDLE) {
            e->last_use = st->clock;
            *out = e;
            return RC_OK;
        }
    }
    for (i = 0; i < RC__VK_SENSOR_SLOTS; ++i) { /* an empty slot, else the least recently used */
        rc__vk_sensor_slot *e = &st->sensors[i];
        if (e->table.buf == VK_NULL_HANDLE) {
            slot = e;
            break;
        }
        if (!slot || e->last_use < slot->last_use) slot = e;
    }
    RC_RETURN_IF(st->ctx, bytes > st->max_binding, RC_ERR_OUT_OF_MEMORY,
                 "vulkan: the sensor's ray table takes %llu bytes; %s binds at most %llu (maxStorageBufferRange)",
                 (unsigned long long)bytes, st->device_name, (unsigned long long)st->max_binding);
    rc__vk_buffer_destroy(st, &slot->table);
    memset(slot, 0, sizeof *slot);
    RC_TRY(rc__vk_buffer_create(st, bytes, RC__VK_MEM_UPLOAD, "sensor ray table", &slot->table));
    fill_table(sensor, model, (unsigned char *)slot->table.map);
    RC_TRY(rc__vk_buffer_flush(st, &slot->table));
    slot->sensor = sensor;
    slot->model = model;
    slot->rays = sensor->rays;
    slot->hash = hash;
    slot->last_use = st->clock;
    *out = slot;
    return RC_OK;
}

void rc__vk_sensor_cache_clear(rc__vk_state *st)
{
    uint32_t i;
    for (i = 0; i < RC__VK_SENSOR_SLOTS; ++i) {
        rc__vk_buffer_destroy(st, &st->sensors[i].table);
        memset(&st->sensors[i], 0, sizeof st->sensors[i]);
    }
}
