/*
 * tool_rack_scene.h - the paper's rack (issue 13; docs/method.md §9), one
 * definition for `cdsp_tool bench --rack` (tools/tool_rack.c) and the
 * rack's instruction-count bench (tests/bench/bench_rack.c, which builds
 * tools/tool_rack_scene.c, needing only lib/'s cdsp.h): two pipes 16 mm in
 * diameter, 300 mm long, axes 100 mm apart, on two 12.68 mm support columns
 * behind them, directional light with 40 % ambient, 0.8 px blur, 2 gray
 * levels of noise, a faintly textured background.
 */
#ifndef CDSP_TOOL_RACK_SCENE_H
#define CDSP_TOOL_RACK_SCENE_H

#include <stdint.h>
#include "cdsp.h"

#define RACK_W 2448
#define RACK_H 2048
#define RACK_F (16.0 / 0.00345) /* 16 mm lens, 3.45 um pixels: 4637.68 px */
#define RACK_R 8.0
#define RACK_HALF 150.0
#define RACK_SPACING 100.0
#define RACK_COLUMN_R (12.68 / 2)

/* The rack with its middle at mid (camera coordinates, mm), the axes along
 * v = unit(cos roll, sin roll, 0.15) and spaced along `side`, the in-plane
 * normal to v of a plane tilted by `tilt` (radians) from the image plane
 * toward the line of sight; the background's texture from texture_seed.
 * Writes the scene *s and the two true axes (c[k], v). */
void tool_rack_place(double tilt, double roll, const double mid[3], uint32_t texture_seed, cdsp_scene *s,
                     double c[2][3], double v[3]);

/* The bench's frames: arrangement arr (0: A, side by side, the plane
 * tilted 15..35 degrees, 600..760 mm away; 1: B, one behind the other,
 * 50..70 degrees), group g < RACK_GROUPS (the tilt, roll and distance step
 * with g), frame f (a few mm apart): the scene and the two axes (c[k], v),
 * as tool_rack_place gives them. */
#define RACK_GROUPS 5
void tool_rack_frame(int arr, int g, int f, cdsp_scene *s, double c[2][3], double v[3]);

/* The rack's camera: RACK_W x RACK_H, fx = fy = RACK_F, the principal
 * point at the centre, no distortion. */
void tool_rack_camera(cdsp_camera *cam);

#endif
