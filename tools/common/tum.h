/* rcutil: trajectories in the TUM format as pose files.
 *
 * One pose a line, "timestamp tx ty tz qx qy qz qw": the TUM RGB-D
 * benchmark's format, which evo and many SLAM and odometry systems write.
 * Numbers are separated by spaces, tabs or commas; lines starting with '#'
 * and blank lines are skipped. The pose is base-to-map, as in a raw pose
 * file; the timestamp must be a finite number and is then dropped (a pose
 * carries no time). rcu_poses_read and rcu_poses_write (poses.h) take this
 * format for paths ending in .tum or .txt. */
#ifndef RCU_TUM_H
#define RCU_TUM_H

#include <stdint.h>

#include "rangecast/rangecast.h"

/* Reads a TUM trajectory into a malloc'd array (free() it). Fails (-1,
 * message in rcu_last_error naming the line) on a line without exactly eight
 * numbers, a non-finite value or one beyond float range, a quaternion far
 * from unit length, or a file without a pose. */
int rcu_tum_read(const char *path, rc_pose **out, uint32_t *count);

/* Writes count poses, pose i at timestamp i * period seconds, each value
 * with the digits that read back to the same float. */
int rcu_tum_write(const char *path, const rc_pose *poses, uint32_t count, double period);

#endif
