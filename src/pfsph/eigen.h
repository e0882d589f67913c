/* Eigen-decomposition of small symmetric matrices (2x2 closed form, 3x3 cyclic Jacobi and closed form), used by
 * the anisotropic filter of the pairwise forces (PF Eqs. 8-10). Double precision throughout. */
#ifndef PFSPH_EIGEN_H
#define PFSPH_EIGEN_H

/* Symmetric 2x2 matrix a (only a[0][1] of the off-diagonal is read). Eigenvalues in descending
 * order into w; v[r][c] holds the eigenvector of w[c] in column c (orthonormal, right-handed). */
void pfsph_eigen_sym2(const double a[2][2], double w[2], double v[2][2]);

/* Symmetric 3x3 matrix a (upper triangle read). Eigenvalues descending into w, eigenvectors as
 * the columns of v (orthonormal). Returns the number of Jacobi sweeps used (<= 32); the
 * off-diagonal norm after the last sweep is below 1e-15 of the matrix norm. */
int pfsph_eigen_sym3(const double a[3][3], double w[3], double v[3][3]);

/* The same in closed form (no iteration; upper triangle read): eigenvalues descending, unit
 * orthogonal eigenvector columns. Eigenvalues accurate to about 1e-8 of the largest magnitude
 * in the worst case (a nearly double eigenvalue: acos near +-1), to round-off otherwise;
 * eigenvectors of a nearly double eigenvalue span its plane but are not unique. A zero matrix
 * gives w = 0 and v = I, a multiple of I gives v = I. For the pair filter (float precision). */
void pfsph_eigen_sym3_fast(const double a[3][3], double w[3], double v[3][3]);

/* The eigenvalues of pfsph_eigen_sym3_fast alone (the same bits), descending. */
void pfsph_eigen_sym3_values(const double a[3][3], double w[3]);

#endif
