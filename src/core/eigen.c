/* Symmetric eigen-solvers for 2x2 (closed form) and 3x3 (cyclic Jacobi) matrices; see eigen.h.
 * Jacobi is chosen over the closed-form cubic because it stays accurate for the nearly
 * degenerate matrices an isotropic neighbourhood produces. */
#include "pfsph/eigen.h"

#include <math.h>

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
