/*
 * rangecast — range sensor simulation by ray tracing triangle meshes.
 *
 * This header is the whole public API and its manual. C99, plain C ABI, also
 * compiles as C++.
 *
 * Example: one VLP-16 scan of a mesh held in the caller's arrays.
 *
 *     rc_context_desc cd = rc_context_desc_default();
 *     rc_context *ctx = NULL;
 *     if (rc_context_create(&cd, &ctx) != RC_OK) return 1;   // one malloc here
 *
 *     rc_scene_desc sd = rc_scene_desc_default();
 *     sd.max_geometries = 1; sd.max_triangles = ntri; sd.max_vertices = nvert;
 *     rc_scene *scene = NULL;
 *     rc_scene_create(ctx, &sd, &scene);
 *
 *     rc_mesh_desc md = rc_mesh_desc_default();
 *     md.vertices = verts; md.vertex_count = nvert;           // float x,y,z
 *     md.indices = tris;   md.triangle_count = ntri;          // uint32 x3
 *     uint32_t geom = 0;
 *     rc_scene_add_mesh(scene, &md, &geom);
 *     rc_scene_commit(scene);                                  // builds the BVH
 *
 *     rc_sensor *lidar = NULL;
 *     rc_sensor_create_preset(ctx, RC_PRESET_VELODYNE_VLP16, &lidar);
 *
 *     rc_pose pose = {{0, 0, 1}, {0, 0, 0, 1}};                // base-to-map
 *     static float ranges[16 * 900];
 *     rc_results res = rc_results_default();
 *     res.attributes = RC_ATTR_RANGES;
 *     res.ranges = ranges; res.capacity = 16 * 900;
 *     if (rc_simulate(ctx, scene, lidar, &pose, 1, &res) != RC_OK)
 *         fprintf(stderr, "%s\n", rc_context_last_error(ctx));
 *     rc_context_destroy(ctx);       // frees scenes and sensors too
 *
 * Conventions used throughout:
 * - Every call that can fail returns rc_status: RC_OK (0) or a negative error.
 *   On failure nothing is written to the caller's output buffers and out-params
 *   keep their previous value, and rc_context_last_error() names the argument.
 * - Every create call takes a descriptor whose first field is struct_size; get one
 *   from rc_<x>_desc_default(). Zero in a field means "default". reserved words
 *   must be zero.
 * - Enumerations are plain uint32_t constants (public layout never depends on
 *   the compiler's enum size or on build options).
 * - Frames: right-handed, x forward, y left, z up (REP 103) unless a field says
 *   otherwise. Quaternions are (x, y, z, w). Lengths in metres, angles in radians.
 * - Thread rules: a context, and everything created from it, is used by one
 *   thread at a time, unless a function says otherwise. Separate contexts may
 *   be used on separate threads at the same time (one per filter or core).
 *   Functions without a context argument are thread-safe.
 * - Memory tiers: with the built-in BVH backend the library allocates only inside
 *   the context's arena (a block the caller hands in, or one malloc at context
 *   creation), and never after rc_context_create. The Embree and Vulkan backends
 *   allocate internally as well; their use is reported in rc_memory_stats.
 */
#ifndef RANGECAST_H
#define RANGECAST_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#if defined(_WIN32) && defined(RANGECAST_SHARED)
#  if defined(RANGECAST_BUILDING)
#    define RC_API __declspec(dllexport)
#  else
#    define RC_API __declspec(dllimport)
#  endif
#elif defined(__GNUC__) && defined(RANGECAST_BUILDING)
#  define RC_API __attribute__((visibility("default")))
#else
#  define RC_API
#endif

/* ------------------------------------------------------------------------ */
/* Version                                                                   */
/* ------------------------------------------------------------------------ */

#define RC_VERSION_MAJOR 0
#define RC_VERSION_MINOR 1
#define RC_VERSION_PATCH 0
/* MAJOR * 10000 + MINOR * 100 + PATCH. */
#define RC_VERSION_NUMBER (RC_VERSION_MAJOR * 10000 + RC_VERSION_MINOR * 100 + RC_VERSION_PATCH)

/* The RC_VERSION_NUMBER the library was built with; bindings compare it with
 * the header they were built against. Thread-safe. */
RC_API uint32_t rc_version_number(void);
/* "MAJOR.MINOR.PATCH", static storage. Thread-safe. */
RC_API const char *rc_version_string(void);

/* ------------------------------------------------------------------------ */
/* Status codes. These values are pinned: they never change once released.   */
/* ------------------------------------------------------------------------ */

typedef int32_t rc_status;

#define RC_OK                      0
#define RC_ERR_INVALID_ARGUMENT   (-1)  /* a NULL pointer, a zero count, a value out of its domain */
#define RC_ERR_INVALID_HANDLE     (-2)  /* a handle that is NULL, destroyed or of another kind      */
#define RC_ERR_MISUSE             (-3)  /* a call at the wrong time (e.g. adding to a full scene)   */
#define RC_ERR_OUT_OF_MEMORY      (-4)  /* the arena (or the system) has no room                    */
#define RC_ERR_CAPACITY           (-5)  /* more than the object was created to hold                 */
#define RC_ERR_UNSUPPORTED        (-6)  /* a backend or feature not built in or not available here  */
#define RC_ERR_BACKEND            (-7)  /* the backend library reported an error (message says it)  */
#define RC_ERR_DEVICE_LOST        (-8)  /* the GPU device was lost; only destroy is allowed after   */
#define RC_ERR_CORRUPT_DATA       (-9)  /* a file or blob that fails its checks                     */
#define RC_ERR_NOT_COMMITTED     (-10)  /* a scene used before rc_scene_commit, or changed since    */
#define RC_ERR_NON_FINITE        (-11)  /* NaN or infinity in vertices, poses or parameters         */
#define RC_ERR_OUT_OF_RANGE      (-12)  /* an index (e.g. a triangle's vertex) past its array       */
#define RC_ERR_STRUCT_SIZE       (-13)  /* a descriptor's struct_size this library does not know    */
#define RC_ERR_IO                (-14)  /* a file could not be read or written                      */

/* Static text for a status ("RC_ERR_OUT_OF_MEMORY: ..."). Never NULL. Thread-safe. */
RC_API const char *rc_status_string(rc_status status);

/* ------------------------------------------------------------------------ */
/* Common types                                                              */
/* ------------------------------------------------------------------------ */

/* Rigid transform: rotate by the unit quaternion, then translate.
 * Layout is exactly 7 floats, x y z qx qy qz qw: a raw pose file maps onto an
 * array of rc_pose. Quaternions are normalised by the library when their norm
 * is within 1e-3 of 1; farther off (or zero, NaN, inf) is RC_ERR_NON_FINITE or
 * RC_ERR_INVALID_ARGUMENT. */
typedef struct rc_pose {
    float position[3];
    float orientation[4]; /* x, y, z, w */
} rc_pose;

/* The same in double, for map coordinates far from the origin (UTM). */
typedef struct rc_pose_d {
    double position[3];
    double orientation[4]; /* x, y, z, w */
} rc_pose_d;

/* Identity pose (0,0,0; 0,0,0,1). Thread-safe. */
RC_API rc_pose rc_pose_identity(void);

/* Log callback: level is one of RC_LOG_*. The library never prints. */
#define RC_LOG_ERROR 1u
#define RC_LOG_WARN  2u
#define RC_LOG_INFO  3u
#define RC_LOG_DEBUG 4u
typedef void (*rc_log_fn)(void *user, uint32_t level, const char *message);

/* Progress callback for long work (a large commit). fraction in [0,1]. Return
 * non-zero to keep going; there is no cancel yet (the return is reserved). */
typedef int (*rc_progress_fn)(void *user, const char *stage, double fraction);

/* ------------------------------------------------------------------------ */
/* Context                                                                   */
/* ------------------------------------------------------------------------ */

typedef struct rc_context rc_context;

#define RC_BACKEND_DEFAULT 0u /* = AUTO */
#define RC_BACKEND_AUTO    0u /* the built-in BVH (README, "Backends and build options") */
#define RC_BACKEND_BVH     1u /* built-in SAH BVH, always present */
#define RC_BACKEND_EMBREE  2u
#define RC_BACKEND_VULKAN  3u

typedef struct rc_context_desc {
    uint32_t struct_size;   /* sizeof(rc_context_desc) */
    uint32_t backend;       /* RC_BACKEND_*; 0 = AUTO */
    uint32_t thread_count;  /* 0 = number of online CPUs; 1 = run on the caller's thread.
                             * Any count: a call too small to split (a few rays, one
                             * small scan) runs on the caller's thread alone. */
    uint32_t flags;         /* RC_CONTEXT_* below; 0 = defaults */
    /* The arena. memory != NULL: the caller's block of memory_size bytes,
     * aligned to 16 (RC_ARENA_ALIGNMENT); the library never calls malloc.
     * memory == NULL: the library mallocs memory_size bytes once, here
     * (0 = RC_DEFAULT_ARENA_SIZE), and on Linux advises it for transparent
     * huge pages (large maps trace faster; a caller's block can be advised
     * the same way with madvise(MADV_HUGEPAGE)). Size it with
     * rc_*_memory_requirements. */
    void *memory;
    size_t memory_size;
    rc_log_fn log;          /* optional */
    void *log_user;
    /* RC_BACKEND_VULKAN: which device. NULL or "" = the first discrete or
     * integrated GPU, else any device (lavapipe); a decimal number picks by
     * index as enumerated; anything else is a case-insensitive substring of
     * the device name. No match: RC_ERR_UNSUPPORTED. Read during create only.
     * (The environment variable RANGECAST_VULKAN_DEVICE is used when NULL.) */
    const char *device;
    /* Most memory, in MiB, the backend may hold outside the arena; 0 =
     * unlimited. Embree: its BVHs and buffers, as its memory monitor counts
     * them, plus the backend's commit tables (rc_memory_stats.backend_bytes).
     * Vulkan: the device memory of its buffers (rc_memory_stats.device_bytes).
     * An allocation that would pass it fails the call that needs it (a
     * commit, a sensor, a simulate) with RC_ERR_OUT_OF_MEMORY and a message
     * naming the budget; a scene whose commit failed stays uncommitted. The
     * built-in backend holds nothing outside the arena and ignores it. */
    uint32_t backend_budget_mib;
    uint32_t reserved[7];   /* must be 0 */
} rc_context_desc;

/* rc_context_desc.flags. RC_CONTEXT_VULKAN_RAY_QUERY (backend
 * RC_BACKEND_VULKAN only, else RC_ERR_INVALID_ARGUMENT): find each ray's
 * nearest hit with VK_KHR_ray_query in the driver's acceleration structures
 * (built at commit from the same meshes) instead of the compute kernel's own
 * BVH walk, which stays the default: no device measured so far ran it faster
 * (docs/benchmarks.md, "Vulkan"), and GPUs with ray tracing hardware are the
 * ones to try it on. Rays, the float64 range refinement and the attributes are
 * the compute kernel's; ids may differ where two triangles tie, and a ray
 * through an edge is as watertight as the driver's test (docs/stability.md).
 * A device without Vulkan 1.2, VK_KHR_acceleration_structure and
 * VK_KHR_ray_query: RC_ERR_UNSUPPORTED naming what is missing. */
#define RC_CONTEXT_VULKAN_RAY_QUERY 0x1u

#define RC_ARENA_ALIGNMENT 16u
#define RC_DEFAULT_ARENA_SIZE ((size_t)256 << 20)
/* Most arena bytes an rc_simulate call borrows per thread while it runs
 * (ordered runs on maps larger than the CPU's cache, projected scans of small
 * maps: rc_simulate): give an arena thread_count times this much beyond the
 * memory requirements to let such calls run so; without the room they run
 * scan by scan in tiles (the same results, slower on those maps). */
#define RC_SIMULATE_SCRATCH_PER_THREAD ((size_t)5u << 20)
/* Hard upper bound on thread_count. */
#define RC_MAX_THREADS 256u

/* A desc with struct_size set and every other field 0 (defaults). Thread-safe. */
RC_API rc_context_desc rc_context_desc_default(void);

/* Bytes of arena the context itself takes (its bookkeeping, the per-thread
 * scratch), before any scene or sensor. Add the scene and sensor requirements to
 * size one block for all of them. Thread-safe.
 * Returns RC_ERR_INVALID_ARGUMENT (NULL), RC_ERR_STRUCT_SIZE, RC_ERR_UNSUPPORTED
 * (backend not built in). */
RC_API rc_status rc_context_memory_requirements(const rc_context_desc *desc, size_t *bytes);

/* Creates a context: checks the desc, sets up the arena (one malloc when no
 * block is given), starts thread_count - 1 worker threads, initialises the
 * backend. On Linux the built-in and Embree backends read the CPU's cache
 * sizes from /sys/devices/system/cpu/cpu0/cache here (open and read, no
 * allocation) to decide which maps are large: the built-in backend's
 * traversals take turns in those, the Embree backend prefetches its hits'
 * triangles; where /sys is unreadable they assume a small cache. *out is set
 * only on RC_OK.
 * Returns RC_ERR_INVALID_ARGUMENT, RC_ERR_STRUCT_SIZE, RC_ERR_OUT_OF_MEMORY
 * (block too small or malloc failed), RC_ERR_UNSUPPORTED (backend absent or no
 * device), RC_ERR_BACKEND. Thread-safe (it touches no shared state). With no
 * context to hold it, a failure's message (naming the desc field, or the
 * backend's own reason, e.g. the Vulkan device that matched nothing) goes to
 * desc->log at RC_LOG_ERROR. Vulkan on NVIDIA's driver: the loader loads the
 * driver at each Vulkan context's creation and unloads it at its destruction,
 * and after about 25 such cycles in one process glibc has no static TLS left
 * for it (RC_ERR_UNSUPPORTED, "no Vulkan driver"); keep one Vulkan context for
 * the life of the process rather than creating one per task. */
RC_API rc_status rc_context_create(const rc_context_desc *desc, rc_context **out);

/* Destroys the context, every scene and sensor created from it, joins the
 * threads, and frees the malloc'd arena (a caller's block is the caller's to
 * free). NULL is a no-op. */
RC_API void rc_context_destroy(rc_context *ctx);

/* The message of the last failed call on this context or on an object created
 * from it ("" when none). Valid until the next call on the context. */
RC_API const char *rc_context_last_error(const rc_context *ctx);

/* The backend actually in use (RC_BACKEND_BVH, _EMBREE or _VULKAN). */
RC_API rc_status rc_context_get_backend(const rc_context *ctx, uint32_t *backend);
/* Number of threads simulate uses (the caller's thread included). */
RC_API rc_status rc_context_get_thread_count(const rc_context *ctx, uint32_t *count);

/* Memory figures, all in bytes. */
typedef struct rc_memory_stats {
    uint32_t struct_size;
    uint32_t reserved0;
    uint64_t arena_size;       /* size of the arena block */
    uint64_t arena_used;       /* bytes allocated in it now (headers included) */
    uint64_t arena_peak;       /* high-water mark of arena_used */
    uint64_t backend_bytes;    /* memory the backend library holds outside the arena (Embree, Vulkan host) */
    uint64_t device_bytes;     /* GPU memory held (Vulkan) */
    uint64_t reserved[4];
} rc_memory_stats;

/* Fills stats (stats->struct_size must be set, as by rc_memory_stats_default). */
RC_API rc_memory_stats rc_memory_stats_default(void);
RC_API rc_status rc_context_get_memory_stats(const rc_context *ctx, rc_memory_stats *stats);

/* Is this backend compiled into the library? (It may still fail at create if,
 * e.g., no Vulkan device is present.) Thread-safe. */
RC_API int rc_backend_available(uint32_t backend);
/* "bvh", "embree", "vulkan", "auto" or "unknown". Thread-safe. */
RC_API const char *rc_backend_name(uint32_t backend);

/* ------------------------------------------------------------------------ */
/* Scenes                                                                    */
/* ------------------------------------------------------------------------ */

typedef struct rc_scene rc_scene;

/* A scene is created with fixed capacities; its arena memory is reserved at
 * create (tables, copies) and at commit (acceleration structure). */
typedef struct rc_scene_desc {
    uint32_t struct_size;
    uint32_t max_geometries;   /* meshes this scene can hold (0 = 1) */
    uint32_t max_instances;    /* instances this scene can hold (0 = none) */
    uint32_t flags;            /* none yet: 0 */
    uint64_t max_triangles;    /* sum of triangles over all its meshes */
    uint64_t max_vertices;     /* sum of vertices over meshes added with RC_MESH_COPY */
    uint64_t max_copied_triangles; /* sum of triangles over meshes added with RC_MESH_COPY */
    /* Map coordinates of the scene's (0, 0, 0). Vertices are given relative to
     * it (float keeps millimetres only within a few km of its origin), poses
     * in map coordinates: simulate subtracts the origin in double before
     * casting rays in float. For UTM-scale maps set it to the map's centre and
     * pass poses with rc_simulate_d. Must be finite; 0 for ordinary maps.
     * Used only when this scene is the one simulated (not as an instance). */
    double origin[3];
    /* RC_BUILD_*: what the commit's acceleration structure favours. Every
     * value gives the same ranges; the built-in backend has one build (binned
     * SAH, about 31 bytes a triangle) and accepts every value. */
    uint32_t build_quality;
    uint32_t reserved[7];
} rc_scene_desc;

/* rc_scene_desc.build_quality. Embree: BALANCED is its default build
 * (RTC_BUILD_QUALITY_MEDIUM); FAST its quickest (LOW, a two-level structure:
 * for maps rebuilt often); HIGH asks for its spatial-split build (HIGH,
 * meant for long thin triangles); COMPACT is BALANCED with
 * RTC_SCENE_FLAG_COMPACT (least memory, slower tracing). On the 1M-triangle
 * sphere (docs/benchmarks.md) FAST built 2.6x faster, held 41% more and
 * traced 4% slower; COMPACT held 43% less and traced 21% slower; HIGH was
 * BALANCED's equal. Embree scenes are always robust (RTC_SCENE_FLAG_ROBUST):
 * its default tests let rays slip through shared edges of closed meshes. */
#define RC_BUILD_BALANCED 0u /* default */
#define RC_BUILD_FAST     1u
#define RC_BUILD_HIGH     2u
#define RC_BUILD_COMPACT  3u

RC_API rc_scene_desc rc_scene_desc_default(void);

/* Exact arena bytes a scene with these capacities takes at its peak (create +
 * commit, the commit's temporary build scratch included) on the context's
 * backend. An arena of rc_context_memory_requirements + the sensors' + this
 * can create, fill and commit it; when the sensors are created before the
 * scene is committed, one byte less fails with RC_ERR_OUT_OF_MEMORY. With
 * several scenes the sum is an upper bound (their scratch is not live at the
 * same time). Holds on a fresh context (no holes left by destroyed objects).
 * The built-in backend reserves its tree's worst case at commit and gives the
 * unused part back afterwards (rc_scene_info.bytes is what it keeps); a commit
 * after rc_scene_add_mesh rebuilds every mesh and needs the whole reservation
 * again, so leave that room free (rc_scene_update_mesh only refits, in place).
 * Embree and Vulkan also allocate outside the arena (rc_memory_stats;
 * rc_context_desc.backend_budget_mib caps it). Capacities whose bytes could
 * pass the address space (on 32-bit builds: from about 16M triangles) are
 * RC_ERR_INVALID_ARGUMENT here and in rc_scene_create. */
RC_API rc_status rc_scene_memory_requirements(const rc_context *ctx, const rc_scene_desc *desc,
                                              size_t *bytes);

/* Creates an empty scene in the context's arena. */
RC_API rc_status rc_scene_create(rc_context *ctx, const rc_scene_desc *desc, rc_scene **out);
/* Frees the scene's memory. A scene still instanced by another scene cannot be
 * destroyed (RC_ERR_MISUSE). NULL is a no-op returning RC_OK. */
RC_API rc_status rc_scene_destroy(rc_scene *scene);

#define RC_MESH_REFERENCE 0u  /* default: the arrays are used in place; keep them alive and unchanged */
#define RC_MESH_COPY      1u  /* the arrays are copied into the arena; the built-in backend's
                                 commit renumbers the copy's vertices in the order its tree
                                 reads them (triangles, their order, corners and every result
                                 unchanged), so a poor vertex order costs nothing (builds for
                                 size, -Os, keep the caller's order) */

typedef struct rc_mesh_desc {
    uint32_t struct_size;
    uint32_t flags;             /* RC_MESH_REFERENCE or RC_MESH_COPY */
    const float *vertices;      /* x, y, z per vertex */
    uint64_t vertex_count;
    uint32_t vertex_stride;     /* bytes between vertices; 0 = 12. Multiple of 4. The array
                                   holds vertex_count * stride bytes (Embree shares arrays of
                                   stride >= 16 in place and copies packed ones). */
    uint32_t reserved0;
    const uint32_t *indices;    /* 3 vertex indices per triangle */
    uint64_t triangle_count;
    uint32_t reserved[8];
} rc_mesh_desc;

RC_API rc_mesh_desc rc_mesh_desc_default(void);

/* Adds a triangle mesh. Checks every vertex is finite (RC_ERR_NON_FINITE) and
 * within 1e9 m of the scene's origin on each axis, every index is <
 * vertex_count (RC_ERR_OUT_OF_RANGE) and zero counts (RC_ERR_INVALID_ARGUMENT). *geom_id is its geometry id in this scene
 * (0, 1, 2 ... in order of adding). The scene must be committed afterwards.
 * Degenerate (zero-area) triangles are allowed and never hit. */
RC_API rc_status rc_scene_add_mesh(rc_scene *scene, const rc_mesh_desc *desc, uint32_t *geom_id);

/* Tells the scene a referenced mesh's vertices changed (same counts). The next
 * commit refits that mesh's BVH instead of rebuilding it (built-in backend;
 * Vulkan rewrites that mesh alone where device memory is mapped). Embree
 * builds one tree over all of a scene's own meshes until one of them is
 * updated; from that commit on (a one-time rebuild) the scene keeps a tree
 * per mesh, and an update refits only that mesh's (0.2 ms for a box beside a
 * 1M-triangle mesh, against 0.2 s to rebuild both before).
 * The vertices are checked again as rc_scene_add_mesh checks them. */
RC_API rc_status rc_scene_update_mesh(rc_scene *scene, uint32_t geom_id);

/* An instance places another scene (holding meshes only, committed) in this one. */
typedef struct rc_instance_desc {
    uint32_t struct_size;
    uint32_t reserved0;
    const rc_scene *source;     /* committed scene of meshes; no instances of instances */
    rc_pose transform;          /* source-to-this-scene, applied after scale */
    float scale[3];             /* per-axis scale; 0 in all three = 1 (uniform use: set all three) */
    uint32_t reserved[8];
} rc_instance_desc;

RC_API rc_instance_desc rc_instance_desc_default(void);

/* Adds an instance; *inst_id is its id (0, 1, 2 ... in order). Scale must be
 * finite with a magnitude in [1e-6, 1e6] in every axis once set (negative
 * mirrors), and the translation within 1e9 m of the scene's origin on each
 * axis: RC_ERR_INVALID_ARGUMENT otherwise. (Outside those a ray in the
 * instance's frame starts where Embree no longer traces it.) */
RC_API rc_status rc_scene_add_instance(rc_scene *scene, const rc_instance_desc *desc, uint32_t *inst_id);
/* Moves an instance (dynamic maps); takes effect at the next commit, which only
 * rebuilds the top level when no mesh changed: Embree's tree over the scene's
 * own meshes is kept, and Vulkan rewrites only the instances and the top
 * level on the device. The transform and scale are checked as in
 * rc_scene_add_instance. */
RC_API rc_status rc_scene_set_instance_transform(rc_scene *scene, uint32_t inst_id,
                                                 const rc_pose *transform, const float scale[3]);

/* Builds (or refits) the acceleration structure. Needed after any add/update/set
 * before simulate. progress may be NULL. Returns RC_ERR_OUT_OF_MEMORY when the
 * arena cannot hold the structure (the scene then stays uncommitted),
 * RC_ERR_INVALID_ARGUMENT for an empty scene, RC_ERR_NOT_COMMITTED when an
 * instanced source scene is not committed. The built-in builder runs on the
 * context's threads and makes the same tree for any thread count; progress is
 * called on the caller's thread only. */
RC_API rc_status rc_scene_commit(rc_scene *scene);
RC_API rc_status rc_scene_commit_with_progress(rc_scene *scene, rc_progress_fn progress, void *user);

/* Axis-aligned bounds of the committed scene (min xyz, max xyz). */
RC_API rc_status rc_scene_get_bounds(const rc_scene *scene, float bounds[6]);

/* Counts of a scene as added (not necessarily committed). */
typedef struct rc_scene_info {
    uint32_t struct_size;
    uint32_t geometry_count;
    uint32_t instance_count;
    uint32_t committed;         /* 1 when simulate can use it */
    uint64_t triangle_count;    /* own meshes only */
    uint64_t bvh_nodes;         /* nodes in the built-in structure (0 for other backends) */
    uint64_t bytes;             /* arena bytes the scene holds now */
    uint64_t reserved[4];
} rc_scene_info;
RC_API rc_scene_info rc_scene_info_default(void);
RC_API rc_status rc_scene_get_info(const rc_scene *scene, rc_scene_info *info);

/* ------------------------------------------------------------------------ */
/* Baked maps                                                                */
/* ------------------------------------------------------------------------ */

/* A baked map is a committed scene's meshes and built-in BVH in one
 * relocatable, versioned, checksummed blob: bake it once (offline, with
 * `rangecast bake`), then load it on the robot in place (from flash or an
 * mmap'd file) with no parsing and no build. The layout is docs/baked-map.md:
 * little-endian floats and uint32s only, the same blob on x86-64, aarch64 and
 * armhf. Loading checks everything traversal relies on (the checksum, every
 * offset, index and child link, and that every box holds what lies below it),
 * so a corrupt or hostile blob is RC_ERR_CORRUPT_DATA, never a crash. */

#define RC_BAKED_MAP_VERSION 1u  /* the blob format this library writes and reads */

/* Writes the scene as a baked map. The scene must be committed, belong to a
 * context on the built-in backend (RC_BACKEND_BVH: the blob holds its tree)
 * and hold meshes only (RC_ERR_UNSUPPORTED for instances). blob NULL: *bytes
 * gets the size and nothing is written. Otherwise capacity must be at least
 * that size (RC_ERR_CAPACITY, nothing written) and *bytes gets the bytes
 * written. The same scene gives the same bytes on every run and thread count.
 * Allocates nothing. */
RC_API rc_status rc_scene_bake(const rc_scene *scene, void *blob, size_t capacity, size_t *bytes);

/* rc_scene_load_baked flags */
#define RC_BAKED_SKIP_CHECKSUM 1u /* trust the bytes (checked once already); the structure is still checked */

/* Exact arena bytes rc_scene_load_baked takes for this blob on the context's
 * backend (the blob itself stays where it is and is not counted). Reads the
 * header only. */
RC_API rc_status rc_scene_baked_memory_requirements(const rc_context *ctx, const void *blob, size_t bytes,
                                                    size_t *arena_bytes);

/* Creates a committed, read-only scene from a baked map, referencing the blob
 * in place: keep it alive and unchanged until the scene is destroyed. blob
 * must be 16-byte aligned (mmap and aligned_alloc give that; malloc does on
 * 64-bit glibc, but only 8 bytes on 32-bit ARM). On the built-in backend the
 * baked tree is used as it is, so ranges are bit-identical to those of the
 * scene that was baked; Embree and Vulkan build their own structure from the
 * blob's meshes. The scene's geometry ids are the baked scene's, its origin
 * is the baked rc_scene_desc.origin, and it can be instanced like any scene
 * of meshes. Adding to or updating it is RC_ERR_MISUSE. Errors: a blob that
 * fails a check is RC_ERR_CORRUPT_DATA (the message names the check), a
 * format version this library does not read is RC_ERR_UNSUPPORTED, no room
 * in the arena is RC_ERR_OUT_OF_MEMORY; nothing is created then. */
RC_API rc_status rc_scene_load_baked(rc_context *ctx, const void *blob, size_t bytes, uint32_t flags,
                                     rc_scene **out);

/* Geometry geom_id of a baked map as a mesh desc that references the blob
 * (vertex_stride 16), e.g. to hand the map to code of your own. Checks the
 * header and that geometry's offsets, not the checksum. A mesh that was
 * copied (RC_MESH_COPY) comes back with its vertices renumbered as the
 * commit ordered them: the same triangles, in the same order, corner by
 * corner. */
RC_API rc_status rc_baked_get_mesh(const void *blob, size_t bytes, uint32_t geom_id, rc_mesh_desc *mesh,
                                   uint32_t *geometry_count);

/* ------------------------------------------------------------------------ */
/* Sensors                                                                   */
/* ------------------------------------------------------------------------ */

typedef struct rc_sensor rc_sensor;

#define RC_SENSOR_SPHERICAL   1u
#define RC_SENSOR_PINHOLE     2u
#define RC_SENSOR_CYLINDRICAL 3u
#define RC_SENSOR_O1DN        4u
#define RC_SENSOR_ONDN        5u

/* Fields every sensor has. */
typedef struct rc_sensor_common {
    float range_min;         /* hits nearer than this read -inf (REP 117); >= 0 */
    float range_max;         /* no hit within this reads +inf; > range_min */
    rc_pose sensor_to_base;  /* mounting: sensor frame in the robot's base frame */
} rc_sensor_common;

/* An angle axis: count values min, min + increment, ... */
typedef struct rc_angle_axis {
    float min;
    float increment;
    uint32_t count;
} rc_angle_axis;

/* Spherical (spinning LiDARs). Ray (row i, column j), i < phi.count, j < theta.count:
 *   theta = theta.min + j * theta.increment   (horizontal, about z, from x towards y)
 *   phi   = phi.min + i * phi.increment       (vertical, up from the x-y plane)
 *   direction = (cos phi cos theta, cos phi sin theta, sin phi)
 * Index of the ray in a scan: i * theta.count + j. */
typedef struct rc_spherical_desc {
    uint32_t struct_size;
    uint32_t reserved0;
    rc_sensor_common common;
    rc_angle_axis theta;
    rc_angle_axis phi;
    uint32_t reserved[8];
} rc_spherical_desc;

/* Pinhole (depth cameras). Pixel (u = column, v = row), with no half-pixel offset:
 *   optical ray o = ((u - cx) / fx, (v - cy) / fy, 1)   (z forward, x right, y down)
 * frame RC_PINHOLE_FRAME_BODY (default): the sensor frame is x forward, y left,
 *   z up, and the direction is normalize(o.z, -o.x, -o.y);
 * frame RC_PINHOLE_FRAME_OPTICAL: the sensor frame is the ROS optical frame
 *   (z forward, x right, y down) and the direction is normalize(o); points and
 *   normals come out in that frame, as ROS depth images expect.
 * ranges are along the ray (not depth z); depth = range * cos(angle to axis).
 * Index: v * width + u. */
#define RC_PINHOLE_FRAME_BODY    0u
#define RC_PINHOLE_FRAME_OPTICAL 1u
typedef struct rc_pinhole_desc {
    uint32_t struct_size;
    uint32_t frame;          /* RC_PINHOLE_FRAME_* */
    rc_sensor_common common;
    uint32_t width, height;
    float fx, fy, cx, cy;    /* pixels */
    uint32_t reserved[8];
} rc_pinhole_desc;

/* Cylindrical (panoramic cameras, rotating line scanners). Ray (row v, column j):
 *   theta = theta.min + j * theta.increment
 *   h     = (cy - v) / fy              (height on a unit-radius cylinder, up is +)
 *   direction = normalize(cos theta, sin theta, h)
 * Index: v * theta.count + j. */
typedef struct rc_cylindrical_desc {
    uint32_t struct_size;
    uint32_t reserved0;
    rc_sensor_common common;
    rc_angle_axis theta;
    uint32_t height;         /* rows */
    float fy, cy;            /* vertical focal length and centre row, pixels */
    uint32_t reserved[8];
} rc_cylindrical_desc;

/* O1Dn: one origin (the sensor frame's), any directions (e.g. Livox rosettes).
 * OnDn: a ray origin per direction too (sensor frame). Directions need not be
 * unit: they are normalised (a zero direction is RC_ERR_INVALID_ARGUMENT).
 * width * height = ray_count lets tools show the scan as an image; 0, 0 means
 * (ray_count, 1). Origins lie within 1e9 m of the sensor on each axis. The
 * arrays are copied into the arena at create. */
typedef struct rc_rays_desc {
    uint32_t struct_size;
    uint32_t reserved0;
    rc_sensor_common common;
    const float *directions; /* 3 per ray */
    const float *origins;    /* 3 per ray: OnDn only (NULL for O1Dn) */
    uint32_t ray_count;
    uint32_t width, height;
    uint32_t reserved[8];
} rc_rays_desc;

RC_API rc_spherical_desc rc_spherical_desc_default(void);
RC_API rc_pinhole_desc rc_pinhole_desc_default(void);
RC_API rc_cylindrical_desc rc_cylindrical_desc_default(void);
RC_API rc_rays_desc rc_rays_desc_default(void);

/* Exact arena bytes a sensor takes (its precomputed ray table; O1Dn and OnDn
 * sensors also keep the order the CPU backends trace their rays in, 8 bytes a
 * ray, made at create: rays sorted by direction and origin so neighbours in a
 * run are near each other; it changes the speed, never a result). */
RC_API rc_status rc_sensor_memory_requirements_spherical(const rc_spherical_desc *desc, size_t *bytes);
RC_API rc_status rc_sensor_memory_requirements_pinhole(const rc_pinhole_desc *desc, size_t *bytes);
RC_API rc_status rc_sensor_memory_requirements_cylindrical(const rc_cylindrical_desc *desc, size_t *bytes);
RC_API rc_status rc_sensor_memory_requirements_rays(uint32_t model, const rc_rays_desc *desc, size_t *bytes);

/* Creators. Each checks every field (non-finite: RC_ERR_NON_FINITE; zero
 * counts, range_min >= range_max, negative ranges, fx <= 0 ...:
 * RC_ERR_INVALID_ARGUMENT) and precomputes the direction table in the arena. */
RC_API rc_status rc_sensor_create_spherical(rc_context *ctx, const rc_spherical_desc *desc, rc_sensor **out);
RC_API rc_status rc_sensor_create_pinhole(rc_context *ctx, const rc_pinhole_desc *desc, rc_sensor **out);
RC_API rc_status rc_sensor_create_cylindrical(rc_context *ctx, const rc_cylindrical_desc *desc, rc_sensor **out);
/* model: RC_SENSOR_O1DN or RC_SENSOR_ONDN. */
RC_API rc_status rc_sensor_create_rays(rc_context *ctx, uint32_t model, const rc_rays_desc *desc, rc_sensor **out);
/* NULL is a no-op. */
RC_API rc_status rc_sensor_destroy(rc_sensor *sensor);

/* Presets. */
#define RC_PRESET_VELODYNE_VLP16   1u /* spherical 16 x 900: phi -15..+15 deg step 2, theta from -180 deg step 0.4, 0.5..130 m */
#define RC_PRESET_OUSTER_OS1_64    2u /* spherical 64 x 1024: phi -22.5..+22.5 deg (45/63 step), 0.3..120 m */
#define RC_PRESET_REALSENSE_D435   3u /* pinhole 848 x 480, 87 x 58 deg field of view, 0.1..10 m, body frame */
#define RC_PRESET_LIVOX_MID40      4u /* O1Dn rosette, 38.4 deg circular field of view, 10,000 rays, 0.1..260 m */
#define RC_PRESET_VELODYNE_VLP16_360 5u /* as VLP16 with 360 columns (1 deg) */
/* 2-D scanners (spherical, one row at phi 0): column j is a ROS LaserScan's
 * ranges[j], theta = angle_min + j * angle_increment, counterclockwise about z. */
#define RC_PRESET_HOKUYO_UST10LX   6u /* 1 x 1081: theta -135..+135 deg step 0.25, 0.06..10 m */
#define RC_PRESET_ROBOTIS_LDS01    7u /* 1 x 360: theta 0..359 deg step 1 (TurtleBot3), 0.12..3.5 m */

/* Looks a preset up by name: "vlp16", "vlp16-360", "os1-64", "d435", "livox-mid40",
 * "ust-10lx", "lds-01".
 * Returns 0 when unknown. Thread-safe. */
RC_API uint32_t rc_preset_from_name(const char *name);
/* The preset's model (RC_SENSOR_*), 0 when unknown. Thread-safe. */
RC_API uint32_t rc_preset_model(uint32_t preset);
/* Fill a desc with the preset (the model must match: RC_ERR_INVALID_ARGUMENT
 * otherwise). The caller may change fields before creating. Thread-safe. */
RC_API rc_status rc_preset_spherical(uint32_t preset, rc_spherical_desc *desc);
RC_API rc_status rc_preset_pinhole(uint32_t preset, rc_pinhole_desc *desc);
/* O1Dn presets: fills desc and writes the preset's directions (3 floats a
 * ray). With directions NULL, only *count is set to the preset's ray count.
 * Otherwise *count is the capacity of directions in rays on input
 * (RC_ERR_CAPACITY, nothing written, when too small) and the ray count on
 * return. Thread-safe. */
RC_API rc_status rc_preset_rays(uint32_t preset, rc_rays_desc *desc, float *directions, uint32_t *count);
/* Creates any preset directly (the O1Dn ones generate their directions). */
RC_API rc_status rc_sensor_create_preset(rc_context *ctx, uint32_t preset, rc_sensor **out);
RC_API rc_status rc_sensor_memory_requirements_preset(uint32_t preset, size_t *bytes);

/* Ouster lidars from their beam intrinsics: what an Ouster sensor reports
 * about itself (its metadata JSON, or the SDK's sensor_info), as the rays of
 * an OnDn sensor whose every ray leaves its own beam origin. For beam
 * u < beams and measurement id v < columns (ray u * columns + v: the sensor's
 * own, staggered, order; rows are beams):
 *   encoder      te = 2 pi (1 - v / columns)     (the rotor turns clockwise seen from above)
 *   azimuth      ta = -azimuths_deg[u]; altitude p = altitudes_deg[u]   (to radians)
 *   direction       = (cos(te + ta) cos p, sin(te + ta) cos p, sin p)   (lidar frame)
 *   beam origin     = (bx cos te, bx sin te, bz)    bx = beam_to_lidar[3], bz = beam_to_lidar[11]
 * both taken through lidar_to_sensor into the sensor frame, millimetres to
 * metres. Simulated points are then where the sensor puts them. The sensor
 * measures range from the lidar axis, not from the beam origin: add
 * beam_offset_m = sqrt(bx^2 + bz^2) / 1000 to a simulated range to get the
 * range it reports. Older metadata gives lidar_origin_to_beam_origin_mm
 * instead of beam_to_lidar: that is bx, with bz = 0. */
typedef struct rc_ouster_desc {
    uint32_t struct_size;
    uint32_t beams;                /* pixels_per_column (16, 32, 64, 128) */
    uint32_t columns;              /* columns_per_frame (512, 1024, 2048) */
    uint32_t reserved0;
    const double *altitudes_deg;   /* beam_altitude_angles: one per beam */
    const double *azimuths_deg;    /* beam_azimuth_angles: one per beam */
    double beam_to_lidar[16];      /* 4x4 row by row, translation in mm; default identity */
    double lidar_to_sensor[16];    /* 4x4 row by row, translation in mm; default Ouster's
                                      (180 degrees about z, 36.18 mm up) */
    uint32_t reserved[8];
} rc_ouster_desc;

RC_API rc_ouster_desc rc_ouster_desc_default(void);

/* Most rays (beams * columns) rc_ouster_rays makes: check before allocating. */
#define RC_OUSTER_MAX_RAYS (1u << 24)

/* Writes the beams * columns rays: origins and directions, 3 floats each
 * (metres; unit vectors), and fills rays (may be NULL) for
 * rc_sensor_create_rays(ctx, RC_SENSOR_ONDN, rays, ...): pointing at the two
 * arrays, shaped beams x columns, range 0.3 .. 120 m (an OS1's; set your
 * model's). beam_offset_m (may be NULL) gets the beam offset above. Checks:
 * counts of at least 1 with at most RC_OUSTER_MAX_RAYS, finite angles and matrices,
 * rigid 3x3 parts (orthonormal within 1e-6, no mirror), the translations
 * used (beam_to_lidar's x and z, lidar_to_sensor's) at most 1e11 mm (1e8 m)
 * a component, non-NULL arrays:
 * RC_ERR_INVALID_ARGUMENT or RC_ERR_NON_FINITE, nothing written. No context:
 * statuses only. Thread-safe. */
RC_API rc_status rc_ouster_rays(const rc_ouster_desc *desc, rc_rays_desc *rays, float *origins, float *directions,
                                double *beam_offset_m);

/* Shape of a sensor's scan. */
typedef struct rc_sensor_info {
    uint32_t struct_size;
    uint32_t model;          /* RC_SENSOR_* */
    uint32_t rows;           /* grid rows (height), 1 for flat O1Dn/OnDn */
    uint32_t columns;        /* grid columns (width) */
    uint32_t rays_per_scan;  /* rows * columns */
    float range_min, range_max;
    uint32_t reserved[5];
} rc_sensor_info;
RC_API rc_sensor_info rc_sensor_info_default(void);
RC_API rc_status rc_sensor_get_info(const rc_sensor *sensor, rc_sensor_info *info);

/* Moves the sensor on the robot (takes effect at the next simulate). */
RC_API rc_status rc_sensor_set_mounting(rc_sensor *sensor, const rc_pose *sensor_to_base);

/* Range noise and dropout, applied to every simulate with this sensor after
 * tracing, the same way on every backend:
 *   a return's range r becomes r + mean + sigma * r^sigma_exponent * z,
 *   z ~ N(0, 1), clamped to [range_min, range_max] (noise never turns a
 *   return into a miss); its point moves along its ray to the new range
 *   (normals and ids stay);
 *   with probability dropout a return is lost instead: hit 0, range +inf,
 *   point and normal NaN, ids RC_INVALID_ID.
 * sigma_exponent 0 gives constant noise (LiDARs), 1 noise proportional to
 * range, 2 the quadratic growth of stereo depth cameras. Misses and -inf
 * (nearer than range_min) are left alone.
 * The numbers come from a counter-based generator keyed by seed, the
 * element index (pose * rays_per_scan + ray) and a draw count: the n-th
 * successful simulate with this sensor since rc_sensor_set_noise uses draw n.
 * The same calls in the same order give the same noise for any thread count
 * and backend; each call gets fresh noise. Returns are told apart by the
 * requested attributes (hits, ranges, points, normals, prim or geom ids): a
 * request of inst_ids alone is left as traced. Results kept on the device
 * (RC_RESULTS_ON_DEVICE) get the same noise from the Vulkan kernel: the same
 * returns lost, and ranges and points equal to the host's where the device
 * has shaderFloat64 (the kernel computes Box-Muller's log and cos in double;
 * lavapipe gave them to the bit), within GLSL's looser log and cos without
 * it (Vulkan bounds cos only to 2^-11 absolute, up to 0.3% of sigma; on
 * lavapipe the largest difference was 1.9e-6 m at sigma 0.03 m). Such a call
 * uses a draw like any other. */
typedef struct rc_noise_desc {
    uint32_t struct_size;
    uint32_t reserved0;
    float mean;            /* m, added to every return (a range bias) */
    float sigma;           /* m at 1 m when sigma_exponent > 0; >= 0 */
    float sigma_exponent;  /* >= 0 */
    float dropout;         /* probability a return is lost, in [0, 1] */
    uint64_t seed;
    uint32_t reserved[8];
} rc_noise_desc;

/* Every field 0 (no noise) but struct_size. Thread-safe. */
RC_API rc_noise_desc rc_noise_desc_default(void);
/* Sets (or with NULL, or a desc whose mean, sigma and dropout are all 0,
 * removes) the sensor's noise and restarts its draw count. Non-finite values:
 * RC_ERR_NON_FINITE; sigma or sigma_exponent < 0, dropout outside [0, 1]:
 * RC_ERR_INVALID_ARGUMENT; a failed call leaves the noise as it was. */
RC_API rc_status rc_sensor_set_noise(rc_sensor *sensor, const rc_noise_desc *noise);

/* ------------------------------------------------------------------------ */
/* Simulate                                                                  */
/* ------------------------------------------------------------------------ */

#define RC_ATTR_HITS     0x01u /* uint8: 1 = a valid return within [range_min, range_max] */
#define RC_ATTR_RANGES   0x02u /* float: metres; +inf no return, -inf nearer than range_min (REP 117) */
#define RC_ATTR_POINTS   0x04u /* float x3: sensor frame; NaN where hit is 0 */
#define RC_ATTR_NORMALS  0x08u /* float x3: sensor frame, unit, facing the sensor; NaN where hit is 0 */
#define RC_ATTR_PRIM_IDS 0x10u /* uint32: triangle index within its mesh; RC_INVALID_ID where hit is 0 */
#define RC_ATTR_GEOM_IDS 0x20u /* uint32: geometry id within its scene; RC_INVALID_ID where hit is 0 */
#define RC_ATTR_INST_IDS 0x40u /* uint32: instance id; RC_INVALID_ID where hit is 0 or the mesh is not instanced */
#define RC_ATTR_ALL      0x7Fu

#define RC_INVALID_ID 0xFFFFFFFFu

/* The caller's result buffers, one array per attribute. Element k of a batch is
 * pose * rays_per_scan + ray (for grid sensors ray = row * columns + column);
 * points and normals hold 3 floats per element. Every requested buffer must hold
 * capacity elements, capacity >= pose_count * rays_per_scan. Buffers of
 * attributes not requested are ignored and left untouched. */
typedef struct rc_results {
    uint32_t struct_size;
    uint32_t attributes;     /* RC_ATTR_* mask */
    uint64_t capacity;       /* elements each requested buffer holds */
    uint8_t *hits;
    float *ranges;
    float *points;
    float *normals;
    uint32_t *prim_ids;
    uint32_t *geom_ids;
    uint32_t *inst_ids;
    uint32_t flags;          /* RC_RESULTS_*; 0 = write the host buffers above */
    uint32_t reserved[7];
} rc_results;

/* Keep the results on the device (Vulkan backend only; other backends return
 * RC_ERR_UNSUPPORTED): the requested attributes stay in one device buffer, for
 * Vulkan consumers that bind it directly, and nothing is copied to the host.
 * The buffer pointers and capacity above are then ignored (may be NULL / 0).
 * rc_context_get_device_results describes the buffer after the call. */
#define RC_RESULTS_ON_DEVICE 0x1u

RC_API rc_results rc_results_default(void);

/* Where the last rc_simulate / rc_simulate_d with RC_RESULTS_ON_DEVICE left its
 * results. The buffer holds one array per requested attribute, element k =
 * pose * rays_per_scan + ray as on the host, at offsets[] (bytes; RC_ATTR_*
 * bit order: hits, ranges, points, normals, prim, geom, inst ids; UINT64_MAX for
 * attributes not requested). Element formats as on the host, except hits:
 * uint32 (0 or 1) on the device. The call waited for the device, so the
 * contents are complete; a consumer's later submission on the same device
 * reads them after its own pipeline barrier. The buffer belongs to the
 * context: valid until the next rc_simulate / rc_simulate_d on it or its
 * destruction; do not free it. Handles are the Vulkan handles' values (VkBuffer
 * is non-dispatchable; instance, physical_device and device are pointers). */
typedef struct rc_device_results {
    uint32_t struct_size;
    uint32_t attributes;      /* RC_ATTR_* held */
    uint64_t elements;        /* pose_count * rays_per_scan of that call */
    uint64_t buffer;          /* VkBuffer */
    uint64_t bytes;           /* bytes of the buffer the arrays span */
    uint64_t offsets[7];
    uint64_t instance;        /* VkInstance */
    uint64_t physical_device; /* VkPhysicalDevice */
    uint64_t device;          /* VkDevice */
    uint32_t queue_family;    /* the queue family the results were written on */
    uint32_t reserved[7];
} rc_device_results;

RC_API rc_device_results rc_device_results_default(void);

/* Fills *out (out->struct_size set by the caller, as rc_device_results_default
 * does). RC_ERR_UNSUPPORTED on a context without a device backend;
 * RC_ERR_INVALID_ARGUMENT when no results are on the device (none simulated
 * with RC_RESULTS_ON_DEVICE since the context's last rc_simulate). */
RC_API rc_status rc_context_get_device_results(rc_context *ctx, rc_device_results *out);

/* Simulates the sensor at pose_count poses (base-to-map) in a committed scene
 * and writes the requested attributes. All arguments are checked before
 * anything is written: NULL handles (RC_ERR_INVALID_HANDLE), a scene and sensor
 * of another context (RC_ERR_INVALID_ARGUMENT), an uncommitted scene
 * (RC_ERR_NOT_COMMITTED), pose_count 0 or a missing buffer
 * (RC_ERR_INVALID_ARGUMENT), capacity too small (RC_ERR_CAPACITY), a NaN/inf
 * pose or a quaternion whose norm is not within 1e-3 of 1 (RC_ERR_NON_FINITE /
 * RC_ERR_INVALID_ARGUMENT; near-unit ones are normalised), a pose that puts
 * the sensor (mounting included) more than 1e9 m from the scene's origin on
 * an axis (RC_ERR_INVALID_ARGUMENT). Runs on the context's
 * threads; results are bit-identical for any thread count. No allocation
 * outside the arena. The built-in and Embree backends, on a map larger than
 * half the CPU's last-level cache and a call of many scans, borrow free arena
 * space while the call runs (16 bytes a tile, at most
 * RC_SIMULATE_SCRATCH_PER_THREAD a thread, shown in rc_memory_stats.arena_peak)
 * to trace the call's tiles in the order of the map rather than scan by scan
 * (faster on maps the cache cannot hold); without that room they run scan by
 * scan. The built-in backend, for a spherical, cylindrical or pinhole sensor
 * on a scene of up to 32 meshes holding together at most one triangle per ray
 * of the scan (for a spherical or cylindrical one, none with an edge longer
 * than a tenth of the meshes' bounding box diagonal), and no instances, borrows 21 bytes a ray a thread (at most
 * RC_SIMULATE_SCRATCH_PER_THREAD: a larger scan goes in bands of rows) to
 * trace each scan triangle by triangle instead (docs/architecture.md,
 * "Projected scans"); a call of fewer than four scans a thread cuts each into
 * bands of rows for the threads. Without the room it takes the tiles. The
 * results are the same bits either way. */
RC_API rc_status rc_simulate(rc_context *ctx, const rc_scene *scene, const rc_sensor *sensor,
                             const rc_pose *poses, uint32_t pose_count, const rc_results *results);

/* rc_simulate with double-precision poses (map coordinates far from the
 * origin, see rc_scene_desc.origin). Same checks, statuses and results. */
RC_API rc_status rc_simulate_d(rc_context *ctx, const rc_scene *scene, const rc_sensor *sensor,
                               const rc_pose_d *poses, uint32_t pose_count, const rc_results *results);

#ifdef __cplusplus
}
#endif
#endif /* RANGECAST_H */
