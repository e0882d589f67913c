/* Measurements of the pair-force liquid shared by its physics and validation tests (compiled
 * into the test support library with testutil.c): static contact angles of drops on plates, and Laplace's
 * law on free drops, in 2D and 3D. Each test is a parameterisation of these: its figures and
 * tolerances are in its own file. */
#ifndef PFSPH_PF_MEASURE_H
#define PFSPH_PF_MEASURE_H

#include <stddef.h>

struct pfsph_ctx;

/* Appends a row (printf-style) to validation/<name> in the working directory, the header line
 * first when the file is new: the data of tools/validation_plots.py (docs/validation.md). */
void pfm_csv_row(const char *name, const char *header, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;

/* ---- contact angles (test_pf_contact_angle.c, _ends.c, test_pf_contact_angle_3d.c) ---- */

#define PFM_MAXDROP 8

/* Contact angle [deg] of the drop whose particles lie in x0 <= x < x1, on a plate whose face is
 * y = 0; NAN if the fit fails. The outline is the farthest particle from the drop's centroid
 * in each of 72 angular sectors (2D) or 12 x 24 bins of solid angle (12 bands equal in cos of
 * the polar angle about y, 24 azimuths; 3D); outline points more than 1.5 d above the face are
 * fitted with a circle or sphere (algebraic least squares, Kasa 1976) whose radius is enlarged
 * by d/2 (particle centres sit half a spacing inside the free surface). With the centre at
 * height y_c above the face and radius R_c the cap meets the plate at cos(theta) = -y_c / R_c. */
double pfm_drop_angle(const struct pfsph_ctx *c, double x0, double x1);
/* The same drop's angle from its centroid height y_c and its volume V = n d^3 alone (3D; NAN in
 * 2D): the spherical cap of volume V whose centroid is y_c above the liquid's base. The base is
 * the mean height of the first layer (particles within d/2 of the lowest) less d/2: on a wetting
 * plate the first layer sits below d/2. Needs no outline, so it gives a figure for caps only a
 * few spacings high, where the fit above 1.5 d has too few points (it saturates near 50 degrees
 * there); it assumes rest density and one cap without a foot. A study figure, printed beside
 * the fit's; no test checks it (docs/pairwise.md, "Contact angles at temperature in 3D"). */
double pfm_drop_angle_cap(const struct pfsph_ctx *c, double x0, double x1);

/* Drops without gravity, each on its own plate (3 layers, face at y = 0) of `pitch` along x
 * (and across z in 3D), starting as the same square (cube) of half side `half` centred on it;
 * sigma 4 N/m, PCISPH, dt_max 0.002 s, the thermostat at its default temperature. */
typedef struct pfm_contact {
    int dim;
    double pitch, half; /* m */
    double top;         /* the domain's top [m] */
    double k;           /* pairwise k */
    int seed;
    const char *nu;        /* water's viscosity, as written in the scene */
    const char *pw;        /* extra pairwise keys ("" for none) */
    double dt_s;           /* time between samples [s] */
    int nsamples;          /* samples, the last at nsamples * dt_s */
    int avg_after;         /* samples 1..avg_after are not averaged */
    double t_avg0, t_avg1; /* the averaging window, for the report */
    double tol;            /* |mean - target| allowed [deg] */
    int cap;               /* 3D: check pfm_drop_angle_cap's angle (else pfm_drop_angle's); both are printed */
} pfm_contact;

/* Run nd drops to their targets [deg] (ratio != NULL: with c_wa = ratio[q] c_aa given directly,
 * the calibration study, target then being Eq. 21's angle of the ratio) and check each: no
 * particle removed, the mean angle over the averaged samples within tol of its target, the
 * lowest particle centre within a spacing of the face (a drop that jumps off has no angle). */
void pfm_contact_run(const pfm_contact *cfg, const double *target, const double *ratio, int nd);
/* The study knobs PF_RATIO and PF_ANG ("a,b,c"): the targets (and ratios) they give; returns
 * their count, or nd with target untouched when neither is set. ratio: PFM_MAXDROP entries. */
int pfm_contact_knobs(double *target, double *ratio, int nd);
/* The drops of the contact-angle tests, nd targets [deg]: 2D, 16 x 16 d squares on plates 0.7
 * m apart, sampled every 0.05 s to 6 s, the second half averaged; 3D, 6 d cubes on plates 0.26
 * m square, every 0.02 s to 2 s, averaged from 1 s; seed 11, k 1.7, nu 1e-3, tolerance 10
 * degrees. Under AddressSanitizer they run 1 s (2D) or 0.04 s (3D) and only the code paths are
 * checked. Knobs for studies: PF_T (end time [s]), PF_TAVG (3D: start of the average), PF_K,
 * PF_NU, PF_HALF (half side of the starting square or cube [m]), PF_SEED, PF_PW (extra pairwise
 * keys), PF_ANG ("a,b,c": targets), PF_RATIO ("a,b,c": Eq. 21 adhesion ratios given as
 * coefficients, bypassing the table; the calibration runs, which in 3D then check nothing). */
void pfm_contact_angles(int dim, const double *targets, int nd);
/* The same with drops of half side `half` on plates `pitch` apart, the angle checked that of
 * pfm_drop_angle_cap when cap is 1 (knobs: PF_HALF, PF_PITCH, PF_CAP; PF_LAYERS prints the first
 * two layers' counts and radii, bins of d centred on y = 0 and d, and the liquid below 0.5 d:
 * its mean height and registry with the plate's lattice; the plate: PF_WALL its thickness in
 * cells (6, filled), PF_SKIN=1 a top layer of its own phase without adhesion, PF_AKINCI=1
 * "layers": 1 so that Akinci's volumes replace V0, PF_BCC=1 a second lattice offset by half a
 * cell (a body-centred wall); docs/pairwise.md, "The wall's thickness and make"). */
void pfm_contact_drops(int dim, const double *targets, int nd, double half, double pitch, int cap);

/* ---- Laplace's law (test_pf_laplace.c, test_pf_laplace_3d.c) ---- */

#define PFM_MAXR 8

/* Lattice drops (discs, balls) of radius radii[i] spacings (d = 1 cm), no gravity, sigma 4 N/m,
 * k 1.7, nu 1e-3, run in parallel, one per thread. The pressure inside is the mechanical
 * pressure the frames carry (pfsph_sim_mechanical_pressure) averaged over the particles within
 * R_e / 2 of the centroid, sampled every `every` steps from t0 to t_end; its mean and block
 * error come from 10 block means. The fit p = a + s x, x = (dim - 1) / R_e, must give s within
 * 15 % of sigma, |a| <= 0.25 sigma / R_max and R^2 >= 0.9 (unless checks is 0: code paths only).
 * Knobs for studies: PF_SEED (7), PF_THETA (the thermostat's reduced temperature). */
typedef struct pfm_laplace {
    int dim;
    const char *solver;      /* "type" */
    const char *solver_keys; /* appended to the solver object (", \"tolerance\": ..." or "") */
    const char *dt_max;      /* as written in the scene */
    int every;
    double t0, t_end;
    int profile; /* 3D: radial profile of the pressure, gyration radius and block means */
    int checks;
} pfm_laplace;

void pfm_laplace_run(const pfm_laplace *cfg, const double *radii, int nr);

/* ---- a 2D bubble's shape (test_pf_rising_bubble_hysing.c, test_hysing_cases.c) ---- */

/* The gas particles' (phase index `gas`) centroid, mean vertical velocity and second moments,
 * and the bubble's outline: the 0.5 level of the Shepard colour field c = sum_gas W / sum W
 * (Wendland, support 2 d) on a grid of d / 2, traced by marching squares; circularity
 * 2 sqrt(pi A) / P of that contour (Hysing et al. 2009's definition). */
typedef struct pfm_bubble {
    double cx, cy, vy;  /* gas centroid and mean vertical velocity */
    double aspect;      /* sqrt(smaller / larger eigenvalue of the gas second moments) */
    double hw;          /* sqrt(<dy^2> / <dx^2>): height over width, < 1 for a flattened bubble */
    double circ;        /* circularity: 2 sqrt(pi A) / perimeter of the 0.5 contour */
    double perim, area; /* that contour's length and enclosed area (marching squares) */
    int ngas;
} pfm_bubble;

void pfm_bubble_measure(const struct pfsph_ctx *c, int gas, pfm_bubble *s);

#endif
