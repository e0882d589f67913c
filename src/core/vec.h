/* Small vectors of three doubles: the dot and cross products, differences and lengths that the
 * geometry code shares (internal, not installed). */
#ifndef PFSPH_VEC_H
#define PFSPH_VEC_H

#include <math.h>

/* Each is the plain expression, left to right, as the hand-written helpers it replaced were:
 * a call rounds exactly as they did (the Release flags, -march=x86-64-v2, have no FMA to contract
 * into), so moving code onto these changes no bit. The output may not alias an input of vec3_cross. */

static inline double vec3_dot(const double a[3], const double b[3]) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

/* o = a x b */
static inline void vec3_cross(const double a[3], const double b[3], double o[3])
{
    o[0] = a[1] * b[2] - a[2] * b[1];
    o[1] = a[2] * b[0] - a[0] * b[2];
    o[2] = a[0] * b[1] - a[1] * b[0];
}

/* o = a - b */
static inline void vec3_sub(const double a[3], const double b[3], double o[3])
{
    o[0] = a[0] - b[0];
    o[1] = a[1] - b[1];
    o[2] = a[2] - b[2];
}

/* |a| */
static inline double vec3_norm(const double a[3]) { return sqrt(vec3_dot(a, a)); }

/* a / |a| in place; a zero vector stays zero */
static inline void vec3_normalize(double a[3])
{
    double l = vec3_norm(a);
    if (l > 0)
        for (int k = 0; k < 3; k++) a[k] /= l;
}

#endif
