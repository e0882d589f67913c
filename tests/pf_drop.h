/* The oscillating drop (docs/validation_drop.md): the l = 2 mode of a free drop of pair-force
 * liquid against Rayleigh's frequency and Lamb's viscous damping, in 2D and 3D; shared by
 * tests/physics/test_pf_drop_oscillation.c and tests/validation/test_pf_drop_oscillation_fine.c. */
#ifndef PFSPH_PF_DROP_H
#define PFSPH_PF_DROP_H

#include <stddef.h>

/* A lattice disc (ball) of radius R [m] at spacing d, water (rho 1000) of tension sigma and
 * viscosity nu as set, no gravity, default temperature, DFSPH, k 1.7 in 2D and Eq. 5's in 3D
 * (the shipped scenes'). It melts at rest for t_melt, then gets the l = 2 potential flow
 *     2D: u = A (x, -y),   3D: u = A (-x / 2, -y / 2, z)   (about the centroid),
 * A = eps0 omega_0, so that the deformation starts from round with rate A; it is then sampled
 * every T_0 / 40 for `periods` Rayleigh periods. */
typedef struct pfm_osc {
    int dim;
    double R, d, sigma, nu, eps0, periods, t_melt;
    int seed;       /* the first thermostat seed */
    int nseeds;     /* realisations averaged (seed, seed + 1, ...); the thermal shape noise falls as
                 * 1 / sqrt(nseeds) */
    const char *pw; /* extra pairwise keys, each followed by a comma (NULL: none); PF_PW overrides */
} pfm_osc;

typedef struct pfm_osc_result {
    double R_e;               /* radius of the disc (ball) of the particles' volume [m] */
    double omega0, T0;        /* Rayleigh: 2D omega^2 = 6 sigma / (rho R^3), 3D 8 sigma / (rho R^3) */
    double gamma_lamb;        /* Lamb: 2D 4 nu / R^2, 3D 5 nu / R^2 (amplitude decay rate) */
    double T_damped;          /* 2 pi / sqrt(omega0^2 - gamma^2) with Lamb's gamma */
    double T, gamma;          /* measured: period from the zero crossings, decay from the peaks */
    int ncross, npeaks;       /* how many of each the fits used */
    size_t n;                 /* particles */
    size_t ns;                /* samples */
    double *t, *s, *s_theory; /* deformation s(t) (second moments, below) and Rayleigh-Lamb's */
    double cpu;               /* seconds of CPU */
} pfm_osc_result;

/* Runs the drop; returns 0, or -1 with a message on stderr (a particle lost, no oscillation).
 * The deformation is 2D (Ixx - Iyy) / (Ixx + Iyy), 3D (Izz - (Ixx + Iyy) / 2) / (Ixx + Iyy + Izz)
 * about the centroid. r->t, r->s, r->s_theory are malloc'ed (pfm_osc_free). */
int pfm_oscillation(const pfm_osc *cfg, pfm_osc_result *r);
void pfm_osc_free(pfm_osc_result *r);
/* Prints the result, and with PF_PLOT=dir set writes dir/drop_<tag>.csv and dir/drop_<tag>.png
 * (the page's figures). */
void pfm_osc_report(const pfm_osc *cfg, const pfm_osc_result *r, const char *tag);

#endif
