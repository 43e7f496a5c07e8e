/* rcutil: pose files (raw, or TUM trajectories: tum.h) and the standard
 * random poses.
 *
 * A raw pose file is a sequence of little-endian float32, 7 per pose:
 * x y z qx qy qz qw (base-to-map), 28 bytes a pose, no header. It maps onto an
 * array of rc_pose exactly. */
#ifndef RCU_POSES_H
#define RCU_POSES_H

#include <stdint.h>

#include "rangecast/rangecast.h"
#include "util.h"

#define RCU_POSE_FILE_BYTES 28u

/* Reads a pose file into a malloc'd array (free() it). Fails (-1, message in
 * rcu_last_error) on an empty file, a size that is not a multiple of 28 bytes,
 * or a non-finite value or a quaternion far from unit length (naming the pose).
 * A path ending in .tum or .txt is read as a TUM trajectory (tum.h). */
int rcu_poses_read(const char *path, rc_pose **out, uint32_t *count);

/* The readers refuse a pose whose quaternion's norm is off 1 by more than
 * this (a file of another layout or order, not rounding). */
#define RCU_POSE_NORM_TOLERANCE 1e-3
/* The norm of a pose's quaternion, in double. */
double rcu_pose_quaternion_norm(const rc_pose *pose);

/* 1 when rcu_poses_read and rcu_poses_write take path as a TUM trajectory
 * (it ends in .tum or .txt). */
int rcu_poses_is_tum(const char *path);

/* Writes count poses; to a .tum or .txt path as a TUM trajectory, poses
 * RCU_TUM_PERIOD seconds apart (a spinning LiDAR's 10 Hz). */
#define RCU_TUM_PERIOD 0.1
int rcu_poses_write(const char *path, const rc_pose *poses, uint32_t count);

/* count poses with positions uniform in the ball of the given radius about
 * the origin and orientations uniformly random unit quaternions (Shoemake),
 * from xoshiro256** seeded by splitmix64(seed): the same seed gives the same
 * poses on every platform (positions by rejection sampling, no libm). */
void rcu_poses_random(uint32_t count, float radius, uint64_t seed, rc_pose *out);
/* The same about center (NULL = origin). */
void rcu_poses_random_about(uint32_t count, float radius, uint64_t seed, const float center[3],
                            rc_pose *out);

/* count incoherent rays for an OnDn sensor: origins uniform in the ball of
 * radius about the sensor frame's origin, directions uniform on the unit
 * sphere (both by rejection sampling; 3 floats each in origins and dirs). */
void rcu_rays_random(uint32_t count, float radius, uint64_t seed, float *origins, float *dirs);

/* The deterministic generator behind rcu_poses_random, for tests. */
typedef struct rcu_rng {
    uint64_t s[4];
} rcu_rng;
void rcu_rng_seed(rcu_rng *rng, uint64_t seed);
uint64_t rcu_rng_next(rcu_rng *rng);
/* Uniform in [0, 1) with 53 random bits. */
double rcu_rng_uniform(rcu_rng *rng);

#endif
