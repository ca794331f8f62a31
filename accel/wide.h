/* accel/wide.h — what the CPU's wide trees (4-wide accel/bvh4.h, 8-wide accel/bvh8.h) share
 * whatever their width: a leaf lane's count flags and the traversal's stack entries.  The walk
 * itself is written once, for either width, in accel/wide_walk.h.
 *
 * A lane's count (uint16_t): 0 for an interior lane, else a leaf's primitive count (at most
 * 32767), or for a packed leaf RS_WIDE_PACKED | its number of blocks (RS_WIDE_BLOCKS), with
 * RS_WIDE_QUADS for parallelogram blocks or RS_WIDE_SPHERES for sphere blocks (8 wide only).
 *
 * A stack entry: an interior node's index, or RS_WIDE_LEAF | node << log2(width) | lane for one
 * leaf lane of a node (so a tree indexes at most 2^31 / width nodes). */
#ifndef RS_ACCEL_WIDE_H
#define RS_ACCEL_WIDE_H

#define RS_WIDE_LEAF    0x80000000u
#define RS_WIDE_PACKED  0x8000u
#define RS_WIDE_QUADS   0x4000u /* with RS_WIDE_PACKED: the blocks are parallelograms */
#define RS_WIDE_SPHERES 0x2000u /* with RS_WIDE_PACKED: sphere blocks (8-wide tree only) */
/* a packed count's number of blocks (a longer leaf stays unpacked) */
#define RS_WIDE_BLOCKS  0x1fffu

#endif
