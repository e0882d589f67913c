/* Symmetric eigen-solvers for 2x2 (closed form) and 3x3 matrices; see eigen.h. The 3x3 comes
 * twice: cyclic Jacobi, accurate to round-off for nearly degenerate matrices (measurements,
 * meshes), and a closed form (Eberly's non-iterative solver) for the pair filter, which needs
 * float precision and calls it once per particle per step. */
#include "pfsph/eigen.h"

#include <math.h>

#include "core/vec.h"

void pfsph_eigen_sym2(const double a[2][2], double w[2], double v[2][2])
{
    double p = a[0][0], q = a[0][1], r = a[1][1];
    double m = 0.5 * (p + r);
    double d = hypot(0.5 * (p - r), q);
    w[0] = m + d;
    w[1] = m - d;
    /* Rotation angle of the principal axis; atan2 stays defined for q = 0 and p = r. */
    double th = 0.5 * atan2(2.0 * q, p - r);
    double c = cos(th), s = sin(th);
    v[0][0] = c;
    v[1][0] = s;
    v[0][1] = -s;
    v[1][1] = c;
}

int pfsph_eigen_sym3(const double a[3][3], double w[3], double v[3][3])
{
    double m[3][3];
    double scale = 0;
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) {
            m[i][j] = i <= j ? a[i][j] : a[j][i];
            v[i][j] = i == j ? 1.0 : 0.0;
            scale += m[i][j] * m[i][j];
        }
    int sweep = 0;
    double tol = 1e-30 * (scale > 0 ? scale : 1.0); /* squared: 1e-15 relative */
    for (; sweep < 32; sweep++) {
        double off = m[0][1] * m[0][1] + m[0][2] * m[0][2] + m[1][2] * m[1][2];
        if (off <= tol) break;
        for (int p = 0; p < 2; p++)
            for (int q = p + 1; q < 3; q++) {
                if (m[p][q] == 0.0) continue;
                /* Rutishauser's stable form of the Jacobi rotation zeroing m[p][q]. */
                double theta = (m[q][q] - m[p][p]) / (2.0 * m[p][q]);
                double t = (theta >= 0 ? 1.0 : -1.0) / (fabs(theta) + sqrt(theta * theta + 1.0));
                double c = 1.0 / sqrt(t * t + 1.0), s = t * c;
                for (int k = 0; k < 3; k++) { /* columns p, q of m */
                    double mkp = m[k][p], mkq = m[k][q];
                    m[k][p] = c * mkp - s * mkq;
                    m[k][q] = s * mkp + c * mkq;
                }
                for (int k = 0; k < 3; k++) { /* rows p, q of m */
                    double mpk = m[p][k], mqk = m[q][k];
                    m[p][k] = c * mpk - s * mqk;
                    m[q][k] = s * mpk + c * mqk;
                }
                for (int k = 0; k < 3; k++) {
                    double vkp = v[k][p], vkq = v[k][q];
                    v[k][p] = c * vkp - s * vkq;
                    v[k][q] = s * vkp + c * vkq;
                }
            }
    }
    for (int i = 0; i < 3; i++) w[i] = m[i][i];
    /* Sort descending, carrying the eigenvector columns. */
    for (int i = 0; i < 2; i++) {
        int best = i;
        for (int j = i + 1; j < 3; j++)
            if (w[j] > w[best]) best = j;
        if (best != i) {
            double t = w[i];
            w[i] = w[best];
            w[best] = t;
            for (int k = 0; k < 3; k++) {
                t = v[k][i];
                v[k][i] = v[k][best];
                v[k][best] = t;
            }
        }
    }
    return sweep;
}

/* The eigenvector of the simple eigenvalue e of the (scaled) matrix m: the largest of the cross
 * products of two rows of m - e I, which spans their orthogonal complement. */
static void evec_simple(const double m[3][3], double e, double out[3])
{
    const double r0[3] = {m[0][0] - e, m[0][1], m[0][2]};
    const double r1[3] = {m[0][1], m[1][1] - e, m[1][2]};
    const double r2[3] = {m[0][2], m[1][2], m[2][2] - e};
    double c[3][3];
    vec3_cross(r0, r1, c[0]);
    vec3_cross(r0, r2, c[1]);
    vec3_cross(r1, r2, c[2]);
    const double d0 = vec3_dot(c[0], c[0]), d1 = vec3_dot(c[1], c[1]), d2 = vec3_dot(c[2], c[2]);
    int k = d0 >= d1 ? (d0 >= d2 ? 0 : 2) : (d1 >= d2 ? 1 : 2);
    const double d = k == 0 ? d0 : (k == 1 ? d1 : d2);
    if (!(d > 0)) { /* m - e I of rank < 2: only for an all-equal spectrum, where any axis is one */
        out[0] = 1, out[1] = 0, out[2] = 0;
        return;
    }
    const double inv = 1.0 / sqrt(d);
    for (int a = 0; a < 3; a++) out[a] = c[k][a] * inv;
}

/* The eigenvector of eigenvalue e orthogonal to the unit eigenvector u0: the 2x2 problem on the
 * plane orthogonal to u0, solved by the larger row so that a double eigenvalue (zero 2x2
 * matrix) or a near one still gives a unit vector in the plane. */
static void evec_plane(const double m[3][3], const double u0[3], double e, double out[3])
{
    double U[3], V[3];
    if (fabs(u0[0]) > fabs(u0[1])) {
        const double inv = 1.0 / sqrt(u0[0] * u0[0] + u0[2] * u0[2]);
        U[0] = -u0[2] * inv, U[1] = 0, U[2] = u0[0] * inv;
    } else {
        const double inv = 1.0 / sqrt(u0[1] * u0[1] + u0[2] * u0[2]);
        U[0] = 0, U[1] = u0[2] * inv, U[2] = -u0[1] * inv;
    }
    vec3_cross(u0, U, V);
    double mU[3], mV[3];
    for (int a = 0; a < 3; a++) {
        mU[a] = m[a][0] * U[0] + m[a][1] * U[1] + m[a][2] * U[2];
        mV[a] = m[a][0] * V[0] + m[a][1] * V[1] + m[a][2] * V[2];
    }
    double m00 = vec3_dot(U, mU) - e, m01 = vec3_dot(U, mV), m11 = vec3_dot(V, mV) - e;
    const double a00 = fabs(m00), a01 = fabs(m01), a11 = fabs(m11);
    double cu = 1, cv = 0; /* out = cu U + cv V */
    if (a00 >= a11) {
        if ((a00 > a01 ? a00 : a01) > 0) {
            if (a00 >= a01) {
                m01 /= m00;
                m00 = 1.0 / sqrt(1.0 + m01 * m01);
                m01 *= m00;
            } else {
                m00 /= m01;
                m01 = 1.0 / sqrt(1.0 + m00 * m00);
                m00 *= m01;
            }
            cu = m01, cv = -m00;
        }
    } else {
        if ((a11 > a01 ? a11 : a01) > 0) {
            if (a11 >= a01) {
                m01 /= m11;
                m11 = 1.0 / sqrt(1.0 + m01 * m01);
                m01 *= m11;
            } else {
                m11 /= m01;
                m01 = 1.0 / sqrt(1.0 + m11 * m11);
                m11 *= m01;
            }
            cu = m11, cv = -m01;
        }
    }
    for (int a = 0; a < 3; a++) out[a] = cu * U[a] + cv * V[a];
}

/* Eigenvalues (descending) of the scaled matrix m = A / s in closed form; returns 0 for a
 * multiple of I (p = 0), else the sign of det(B) / 2 (which eigenvalue is the farther from the
 * middle one) as 1 (the largest) or -1. D. Eberly, "A robust eigensolver for 3x3 symmetric
 * matrices" (Geometric Tools, 2014): the trigonometric solution of the characteristic cubic of
 * the shifted, scaled B = (m - q I) / p. */
static int values_scaled(const double m[3][3], double e[3])
{
    const double q = (m[0][0] + m[1][1] + m[2][2]) / 3.0;
    const double b00 = m[0][0] - q, b11 = m[1][1] - q, b22 = m[2][2] - q;
    const double off = m[0][1] * m[0][1] + m[0][2] * m[0][2] + m[1][2] * m[1][2];
    const double p = sqrt((b00 * b00 + b11 * b11 + b22 * b22 + 2.0 * off) / 6.0);
    if (!(p > 0)) {
        e[0] = e[1] = e[2] = q;
        return 0;
    }
    /* det(B) / 2 = cos(3 phi), B's eigenvalues 2 cos(phi + 2 pi k / 3) */
    const double c00 = b11 * b22 - m[1][2] * m[1][2];
    const double c01 = m[0][1] * b22 - m[1][2] * m[0][2];
    const double c02 = m[0][1] * m[1][2] - b11 * m[0][2];
    double hd = 0.5 * (b00 * c00 - m[0][1] * c01 + m[0][2] * c02) / (p * p * p);
    hd = hd < -1 ? -1 : (hd > 1 ? 1 : hd);
    const double phi = acos(hd) / 3.0;
    const double beta2 = 2.0 * cos(phi), beta0 = 2.0 * cos(phi + 2.0943951023931954923);
    const double beta1 = -(beta0 + beta2);
    e[0] = q + p * beta2;
    e[1] = q + p * beta1;
    e[2] = q + p * beta0;
    return hd >= 0 ? 1 : -1;
}

/* the largest |a_ij| of the upper triangle (0 for a zero matrix, NaN-free: fmax drops NaN) */
static double max_abs(const double a[3][3])
{
    double s = 0;
    for (int i = 0; i < 3; i++)
        for (int j = i; j < 3; j++) s = fmax(s, fabs(a[i][j]));
    return s;
}

void pfsph_eigen_sym3_values(const double a[3][3], double w[3])
{
    const double s = max_abs(a);
    if (!(s > 0)) {
        w[0] = w[1] = w[2] = 0;
        return;
    }
    const double is = 1.0 / s;
    const double m[3][3] = {{a[0][0] * is, a[0][1] * is, a[0][2] * is},
                            {a[0][1] * is, a[1][1] * is, a[1][2] * is},
                            {a[0][2] * is, a[1][2] * is, a[2][2] * is}};
    double e[3];
    values_scaled(m, e);
    for (int k = 0; k < 3; k++) w[k] = e[k] * s;
}

void pfsph_eigen_sym3_fast(const double a[3][3], double w[3], double v[3][3])
{
    /* Eberly (values_scaled): the eigenvector of the eigenvalue farther from the middle one from
     * cross products (well separated by construction), the middle one in the plane orthogonal
     * to it, the third their cross product. */
    const double s = max_abs(a);
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) v[i][j] = i == j ? 1.0 : 0.0;
    if (!(s > 0)) { /* zero matrix (or NaN): zero spectrum, the axes */
        w[0] = w[1] = w[2] = 0;
        return;
    }
    const double is = 1.0 / s;
    const double m[3][3] = {{a[0][0] * is, a[0][1] * is, a[0][2] * is},
                            {a[0][1] * is, a[1][1] * is, a[1][2] * is},
                            {a[0][2] * is, a[1][2] * is, a[2][2] * is}};
    double e[3]; /* descending */
    const int far = values_scaled(m, e);
    if (far == 0) { /* a multiple of I: every axis is an eigenvector */
        w[0] = w[1] = w[2] = e[0] * s;
        return;
    }
    double u[3][3]; /* u[k]: unit eigenvector of e[k] */
    if (far > 0) {  /* the largest is the farther from the middle one */
        evec_simple(m, e[0], u[0]);
        evec_plane(m, u[0], e[1], u[1]);
        vec3_cross(u[0], u[1], u[2]);
    } else {
        evec_simple(m, e[2], u[2]);
        evec_plane(m, u[2], e[1], u[1]);
        vec3_cross(u[1], u[2], u[0]);
    }
    for (int k = 0; k < 3; k++) {
        w[k] = e[k] * s;
        for (int r = 0; r < 3; r++) v[r][k] = u[k][r];
    }
}
