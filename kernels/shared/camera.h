/* camera.h: primary rays. Pixel (0,0) is the top-left corner; (jx, jy) in [0,1)² jitters the sample inside
 * it. A thin lens of radius lens_radius focuses at focus_distance along the view axis (pbrt-v4 §5.2.3). */
#ifndef NARVAL_CAMERA_H
#define NARVAL_CAMERA_H

#include "shared/sampling.h"
#include "shared/structs.h"

/* -DCAMERA_PINHOLE (scene specialisation, host/render/kernel_features.h): lens_radius not positive,
 * which the runtime test also takes as a pinhole; bit for bit. */
#ifdef CAMERA_PINHOLE
#define CAMERA_HAS_LENS(c) 0
#else
#define CAMERA_HAS_LENS(c) ((c)->lens_radius > 0.0f)
#endif

typedef struct ray3 {
  vec3 origin;
  vec3 dir; /* unit length */
} ray3;

static inline ray3 camera_ray(NV_CONSTANT const camera_params* c, float px, float py, float lens_u,
                              float lens_v) {
  const float sx = (2.0f * px / (float)c->width - 1.0f) * c->tan_half_vfov * c->aspect;
  const float sy = (1.0f - 2.0f * py / (float)c->height) * c->tan_half_vfov;
  const vec3 fwd = vec3_from4(c->forward), right = vec3_from4(c->right), up = vec3_from4(c->up);
  vec3 dir = vec3_normalize(vec3_add(fwd, vec3_add(vec3_scale(right, sx), vec3_scale(up, sy))));
  vec3 origin = vec3_from4(c->position);
  if (CAMERA_HAS_LENS(c)) {
    float lx, ly;
    sample_concentric_disk(lens_u, lens_v, &lx, &ly);
    const vec3 focus = vec3_madd(origin, dir, c->focus_distance / vec3_dot(dir, fwd));
    origin = vec3_add(origin, vec3_add(vec3_scale(right, c->lens_radius * lx), vec3_scale(up, c->lens_radius * ly)));
    dir = vec3_normalize(vec3_sub(focus, origin));
  }
  ray3 r;
  r.origin = origin;
  r.dir = dir;
  return r;
}

/* Where world point x lies in camera c's image, in pixels ((0, 0) the top-left corner): the inverse of
 * camera_ray through the lens's centre. 0 when x is not in front of the camera. */
static inline int camera_project(NV_PRIVATE const camera_params* c, vec3 x, NV_PRIVATE float* px,
                                 NV_PRIVATE float* py) {
  const vec3 d = vec3_sub(x, vec3_from4(c->position));
  const float z = vec3_dot(d, vec3_from4(c->forward));
  if (!(z > 0.0f)) return 0;
  const float sx = vec3_dot(d, vec3_from4(c->right)) / (z * c->tan_half_vfov * c->aspect);
  const float sy = vec3_dot(d, vec3_from4(c->up)) / (z * c->tan_half_vfov);
  *px = 0.5f * (sx + 1.0f) * (float)c->width;
  *py = 0.5f * (1.0f - sy) * (float)c->height;
  return 1;
}

/* The real-time kernels' ray of pixel (px, py): through its centre, from the lens's centre (they
 * are deterministic: no jitter, no depth of field). */
static inline ray3 camera_pixel_centre_ray(NV_CONSTANT const camera_params* c, int px, int py) {
  return camera_ray(c, (float)px + 0.5f, (float)py + 0.5f, 0.5f, 0.5f);
}

#endif
