/* The physical model's parameters: phase table, pair forces, particle shifting, diffuse
 * material. Core data: the scene loader fills them and the physics reads them, so neither the
 * scene nor the physics includes the other (docs/architecture.md). */
#ifndef PFSPH_PARAMS_H
#define PFSPH_PARAMS_H

#include <stdbool.h>

#include "pfsph/types.h"

#define PFSPH_NAME_LEN 64
/* most scene keys a pressure solver may have of its own (src/physics/solver.h) */
#define PFSPH_SOLVER_MAX_KEYS 8

enum pfsph_phase_kind { PFSPH_PHASE_FLUID = 0, PFSPH_PHASE_GAS = 1, PFSPH_PHASE_SOLID = 2 };

typedef struct pfsph_phase {
    char name[PFSPH_NAME_LEN];
    int kind;            /* enum pfsph_phase_kind */
    double rest_density; /* kg/m^3 */
    double viscosity;    /* kinematic, m^2/s */
    float color[3];      /* 0..1 */
    bool color_set;      /* "color" given in the scene (walls are drawn grey otherwise) */
} pfsph_phase;

/* ---- particle shifting (physics/shifting.c, src/pfsph/shifting.h) ---- */

typedef struct pfsph_shift_params {
    double D;        /* shifting diffusivity [m^2/s]; the shift of one step is
                        -(D + A h |v_i|) dt grad C; D = A = 0 switches shifting off */
    double A;        /* speed-proportional part (Skillen et al. 2013: D_i = A h |v_i|) */
    double surface;  /* C_i below this marks a free-surface particle (C = 1 in the bulk):
                        only the tangential part of its shift is kept */
    double max_frac; /* largest shift in one step, as a fraction of the spacing */
} pfsph_shift_params;

/* Default: off (D = 0, A = 0), surface 0.9, max_frac 0.05. */
void pfsph_shift_defaults(pfsph_shift_params *p);

/* ---- pair forces (physics/pairwise.c, src/pfsph/pairwise.h) ---- */

/* Where the covariance of Eq. 7 is centred. */
enum pfsph_pw_center {
    PFSPH_PW_CENTER_PARTICLE = 0, /* x_i, Eq. 7 as written (default). At k h ~ 2.8 d a particle
                                     on a flat surface sees C_n/C_t ~ 0.66 (square lattice): the
                                     surface row counts in C_t only; in the continuum limit the
                                     moments about x_i are even in the normal and the edge
                                     particle would look isotropic */
    PFSPH_PW_CENTER_MEAN = 1,     /* kernel-weighted mean of the neighbourhood (Yu & Turk 2013):
                                     a stronger, resolution-independent signal at surfaces */
};

/* ---- thermostat of the pair-force liquid (physics/thermostat.c, docs/thermostat.md) ---- */

/* A pairwise random force whose fluctuation-dissipation partner is the SPH viscosity already in
 * the step (smoothed DPD, Espanol & Revenga 2003): it gives the liquid a temperature kT, so
 * that the pair-force fluid flows instead of freezing into a cohesive particle solid. */
/* Default reduced temperature kT / (sigma d^(dim-1)) in 3D: about twice the measured melting
 * point (docs/thermostat.md). */
#define PFSPH_THERMO_REDUCED_DEFAULT 0.01
/* The 2D default. At 0.01 the 2D liquid, 1.7x above its melting point, is a shear-thinning soft
 * glass with an apparent yield stress (drops stay elongated and ring at 4x Lamb's damping); at
 * 0.04 it is Newtonian and flows with the set viscosity, the Morris viscosity applied as set
 * (wall-free slab 1.04-1.15x, drops 0.90-1.05x; docs/viscosity.md). A default of 0.04 was tried
 * and not kept: a 2D film bubble loses its gas there and Hysing's case 1 moves 2x further from
 * the benchmark (the water-gas tension needs a factor of the pair's own temperature first;
 * docs/viscosity.md, "2D: the Newtonian liquid at theta 0.04"). Scenes that want the Newtonian liquid set 0.04. */
#define PFSPH_THERMO_REDUCED_DEFAULT_2D 0.01
/* The temperature the 2D wall-free viscosity table was measured at (params.c) */
#define PFSPH_VISC_TABLE_THETA_2D 0.04
/* The default reduced temperature of a dim-dimensional scene. */
static inline double pfsph_thermo_reduced_default(int dim)
{
    return dim == 2 ? PFSPH_THERMO_REDUCED_DEFAULT_2D : PFSPH_THERMO_REDUCED_DEFAULT;
}

typedef struct pfsph_thermostat_params {
    bool enabled;   /* default: on wherever pair forces act */
    double kT;      /* k_B T [J] (2D: J per metre of depth); < 0: from `reduced` */
    double reduced; /* kT = reduced * sigma_ref * d^(dim-1) when kT is not given */
    /* Filled by pfsph_pairwise_resolve. */
    double kT_resolved; /* the temperature the step uses; 0: thermostat off */
    double sigma_ref;   /* largest liquid-air surface tension of the coefficient table */
    double rho_ref;     /* rest density of that liquid: kT is its temperature */
} pfsph_thermostat_params;

typedef struct pfsph_pairwise_params {
    bool enabled;
    double k;                       /* radius enlargement, default (80/30)^(1/3) (Eq. 5) */
    bool filter;                    /* anisotropic filter on (Eq. 12) */
    double eta;                     /* Eq. 11, default 0.2 */
    double eps_min;                 /* Eq. 8 clamp on eigenvalues normalised by the largest one, default 0.5 */
    int center;                     /* enum pfsph_pw_center */
    pfsph_shift_params shift;       /* particle shifting stage (off unless the scene asks) */
    pfsph_thermostat_params thermo; /* thermal noise (on unless the scene says otherwise) */
    /* Coefficient matrix c[a][b] over scene phases (solids included), symmetric, >= 0.
     * Pair force c m_i m_j f(r): c in N/kg^2 in 3D; in 2D masses are per metre of depth. */
    double c[PFSPH_MAX_PHASES][PFSPH_MAX_PHASES];
    /* Which entries the scene stated (c directly, sigma, or contact angle). */
    bool c_set[PFSPH_MAX_PHASES][PFSPH_MAX_PHASES];
    /* Targets as written in the scene; resolved into c by pfsph_pairwise_resolve. */
    bool sigma_set[PFSPH_MAX_PHASES][PFSPH_MAX_PHASES];
    double sigma[PFSPH_MAX_PHASES][PFSPH_MAX_PHASES]; /* N/m (2D: N/m per metre of depth) */
    bool angle_set[PFSPH_MAX_PHASES][PFSPH_MAX_PHASES];
    double angle_deg[PFSPH_MAX_PHASES][PFSPH_MAX_PHASES];
    /* Filled by pfsph_pairwise_resolve (for the report). */
    bool resolved;
    double radius;       /* k*h [m] */
    double lambda;       /* Eq. 13 constant for the cosine force [m^(dim+2)] */
    double theta;        /* reduced temperature kT / (sigma_ref d^(dim-1)); 0: thermostat off */
    double sigma_factor; /* measured tension / Eq. 13 at theta (pfsph_pairwise_sigma_factor) */
    /* the same for each fluid pair at its own reduced temperature theta_ab = kT_ab /
     * (sigma13_ab d^(dim-1)), kT_ab the pair's (the colder phase's) temperature; the factor its
     * tension target was converted with (solid pairs: sigma_factor) */
    double sigma_factor_ab[PFSPH_MAX_PHASES][PFSPH_MAX_PHASES];
    /* Viscosity correction (docs/viscosity.md): the hot pair-force liquid flows with more than the
     * Morris viscosity it is given, measured wall-free as nu_eff(nu_morris)
     * (pfsph_pairwise_visc_eff); with `viscosity_correction` on (the default in a "pairwise"
     * block, 2D since 2026-12-06) each pair-force phase's Morris viscosity becomes the one that
     * gives its `viscosity`, at least nu_floor, where pfsph_pairwise_visc_corrects holds (3D at
     * 0.01, 2D at 0.01); 2D at 0.04 (Newtonian) and away from the tables: applied as set. */
    bool visc_correct;                  /* scene key; on in a "pairwise" block unless it says false */
    double nu_morris[PFSPH_MAX_PHASES]; /* the viscosity the step applies [m^2/s] */
    double nu_struct[PFSPH_MAX_PHASES]; /* expected bulk viscosity (wall-free table); 2D with the
                                           box correction or off its default temperature: the
                                           box's structural estimate (0: no table) */
    double nu_floor[PFSPH_MAX_PHASES];  /* smallest Morris viscosity applied */
} pfsph_pairwise_params;

void pfsph_pairwise_defaults(pfsph_pairwise_params *p);

/* The pair force shape of Eq. 6: cos(3 pi r / (2 R)) for r <= R, 0 beyond (R = k h). Positive
 * (repulsive) below R/3, negative (attractive) between R/3 and R. */
double pfsph_pairwise_shape(double r, double R);

/* lambda of Eq. 13 for the cosine force over radius R, from the Kirkwood-Buff integral for a
 * step density profile (docs/pairwise.md): sigma = lambda * c * n^2 m^2 = lambda c rho^2.
 * 3D: (pi/8) R^5 (U^4 - 12 U^2 + 24) / U^5; 2D: (1/3) R^4 (U^3 - 6 U - 6) / U^4; U = 3 pi / 2. */
double pfsph_pairwise_lambda(int dim, double R);

/* Surface tension at temperature: the measured tension of the pair-force liquid divided by
 * Eq. 13's lambda c rho^2, at reduced temperature theta = kT / (lambda c rho^2 d^(dim-1))
 * (docs/thermostat.md, "Surface tension at temperature"). A table measured in 2D and one in 3D,
 * interpolated linearly, held at their ends; 1 for theta <= 0 (thermostat off). */
double pfsph_pairwise_sigma_factor(int dim, double theta);
/* Contact angle -> Eq. 21's adhesion ratio r = c_wa rho_w / (c_aa rho_a) at reduced
 * temperature theta: tables measured in 2D and in 3D at the default temperature
 * (docs/pairwise.md, "Contact angles at temperature"); Eq. 21, r = (1 + cos angle) / 2, with the
 * thermostat off (theta <= 0). Angles more wetting than a table reaches extend its last
 * segment. */
double pfsph_pairwise_angle_ratio(int dim, double theta, double angle_deg);
/* The inverse: the static angle [deg] expected for ratio r. */
double pfsph_pairwise_angle_expected(int dim, double theta, double r);
/* The largest ratio the table of dimension dim measured (1 where there is none). */
double pfsph_pairwise_angle_ratio_max(int dim);
/* Whether a measured angle table applies (dimension dim at theta), rather than Eq. 21. */
bool pfsph_pairwise_angle_measured(int dim, double theta);
/* The largest theta of that table: beyond it the factor is extrapolated as a constant. */
double pfsph_pairwise_sigma_theta_max(int dim);
/* Structural viscosity of the hot pair-force liquid in units of sqrt(sigma d / rho) (sigma the
 * phase's own tension at temperature, d the spacing, rho its rest density), at its reduced
 * temperature theta; measured in 2D with bench/pf_visc.c (docs/thermostat.md, "The viscosity of
 * the hot liquid"). 0 where no table applies (3D, theta <= 0). Held at the table's ends. */
double pfsph_pairwise_visc_struct(int dim, double theta);
/* What the Morris viscosity counts for in the hot liquid: nu_eff = nu_struct + GAIN nu_morris
 * (measured 2.0 and 2.2 for rho 1000 at sigma 4 and 24.5; 1.5-7.4 over the other liquids
 * measured, docs/thermostat.md). */
#define PFSPH_VISC_GAIN 2.0
/* The bulk viscosity of the hot pair-force liquid, nu_eff / nu_0, for the Morris viscosity
 * x = nu_morris / nu_0 (nu_0 = sqrt(sigma d / rho), sigma the phase's own tension at temperature,
 * d the spacing, rho its rest density), measured wall-free at the default temperature of
 * dimension dim (2D: at 0.01, its default, and at 0.04, where it is Newtonian and the table
 * serves only the expectation; docs/viscosity.md); NAN where no table applies (theta more than
 * 25 % from a table's). pfsph_pairwise_visc_morris is its inverse: the x that gives nu_eff / nu_0 = y. */
double pfsph_pairwise_visc_eff(int dim, double theta, double x);
double pfsph_pairwise_visc_morris(int dim, double theta, double y);
/* Whether `viscosity_correction` applies the table at theta: 3D at its default temperature, 2D
 * at its default 0.01; not 2D at 0.04 (Newtonian there: the Morris viscosity as set). */
bool pfsph_pairwise_visc_corrects(int dim, double theta);
/* The smallest Morris viscosity the correction applies, in units of sqrt(sigma d / rho): the
 * thermostat's noise is the fluctuation-dissipation partner of that friction, and at 0.047 of
 * the unit the kinetic temperature already reads 0.89 of its value at 0.16 (docs/thermostat.md). */
#define PFSPH_VISC_FLOOR 0.05

/* ---- bubbles in air: two-phase film particles (physics/film.c, src/pfsph/film.h) ---- */

#define PFSPH_MAX_BUBBLES 250 /* bubble k is stored as k + 1 in the uint8 particle field */

/* PF Section 4.2.2: a bubble is a droplet of a gas phase whose outermost particles (surface
 * detection) each carry the same liquid volume fraction a of a film phase; the fraction follows
 * the surface count so that the film's liquid volume stays V_L (docs/film.md). */
typedef struct pfsph_film_params {
    int nbubbles;
    int film[PFSPH_MAX_PHASES];          /* per gas phase: its bubbles' film liquid phase, -1: none */
    int gas[PFSPH_MAX_BUBBLES];          /* the bubble's gas phase */
    int block[PFSPH_MAX_BUBBLES];        /* the scene block it came from (messages) */
    double thickness[PFSPH_MAX_BUBBLES]; /* film thickness at the start [m], 0: volume given */
    double volume[PFSPH_MAX_BUBBLES];    /* liquid volume of the film [m^dim; 2D m^2 per metre];
                                            from the thickness: filled by the simulation */
} pfsph_film_params;

/* No bubbles; film[] = -1. */
void pfsph_film_defaults(pfsph_film_params *p);

/* ---- diffuse material (physics/diffuse.c, src/pfsph/diffuse.h) ---- */

/* Diffuse particle types, stored in pfsph_particles.phase. */
enum pfsph_diffuse_type {
    PFSPH_DIFFUSE_SPRAY = 0,
    PFSPH_DIFFUSE_FOAM = 1,
    PFSPH_DIFFUSE_BUBBLE = 2,
    PFSPH_DIFFUSE_NTYPES = 3
};

/* Per-type weights of Eq. 24 and Eq. 29. */
typedef struct pfsph_diffuse_coupling {
    double k_ext; /* weight of gravity g dt [-] */
    double k_b;   /* buoyancy: adds -k_b g dt [-]; a bubble rises when k_b > k_ext */
    double k_cp;  /* fraction of (v_fluid - v_d) applied per step, in [0, 1] [-] */
    double k_t;   /* lifetime falls by k_t dt per step [-] */
} pfsph_diffuse_coupling;

typedef struct pfsph_diffuse_params {
    bool enabled;
    long max_particles;                /* cap on live diffuse particles; new ones are refused beyond it */
    double sampling_rate;              /* k_max of Eq. 16 [1/s]: particles per second per emitter at R_D=1 */
    double phi_v_min, phi_v_max;       /* Eq. 14 limits for v_diff of Eq. 13 [m/s] */
    double phi_e_min, phi_e_max;       /* Eq. 14 limits for E of Eq. 9 [J] */
    double energy_mass;                /* mass in Eq. 9 [kg]; 0: the fluid particle's own mass */
    double emit_radius;                /* cylinder radius r of Eq. 19 [m]; 0: the particle radius */
    double emit_radius_scale;          /* s_r (paper's k_r magnification, NOTES 16) [-] */
    double emit_height_scale;          /* s_h (paper's k_h magnification) [-] */
    double lifetime_min, lifetime_max; /* initial lifetime uniform in [min, max] [s] */
    int foam_min_neighbors;            /* fewer fluid neighbours within h: spray; -1: automatic */
    int foam_max_neighbors;            /* more: bubble; -1: automatic (NOTES 18) */
    pfsph_diffuse_coupling type[PFSPH_DIFFUSE_NTYPES]; /* spray, foam, bubble */
} pfsph_diffuse_params;

/* Defaults: docs/diffuse.md (the paper's Section 6 values where it gives them). */
void pfsph_diffuse_defaults(pfsph_diffuse_params *p);

/* Thresholds after resolving the automatic (-1) ones for a kernel support h and spacing d in
 * dim dimensions: 0.2 and 2/3 of the fluid neighbour count of a full support (the paper's 6 and
 * 20 of 30). */
void pfsph_diffuse_thresholds(const pfsph_diffuse_params *p, int dim, double h, double spacing, int *foam_min,
                              int *foam_max);

/* ---- emitters (physics/emitter.c, src/pfsph/emitter.h; docs/emitters.md) ---- */

#define PFSPH_MAX_EMITTERS 16

/* Nozzle shapes: a disc or a rectangle in 3D, a segment in 2D. */
enum pfsph_nozzle { PFSPH_NOZZLE_DISC = 0, PFSPH_NOZZLE_RECTANGLE = 1, PFSPH_NOZZLE_SEGMENT = 2 };

/* A nozzle that feeds particles of one phase into the scene. Its exit plane is normal to `axis`
 * (the largest component of `direction`) and passes through `center`; particles enter on the
 * scene lattice's sites of that plane, layer after layer. */
typedef struct pfsph_emitter_params {
    int shape;           /* enum pfsph_nozzle */
    int phase;           /* a fluid or gas phase */
    double center[3];    /* centre of the exit plane [m] */
    double direction[3]; /* unit vector of the entry velocity */
    int axis;            /* 0 x, 1 y, 2 z: the exit plane's normal (from direction) */
    double radius;       /* DISC [m] */
    double size[2];      /* RECTANGLE: extents along the other two axes in x, y, z order [m];
                          * SEGMENT: size[0], its length along the other axis [m] */
    double speed;        /* entry speed along direction [m/s]; 0: from rate */
    double rate;         /* volume rate [m^3/s, m^2/s in 2D]; 0: from speed */
    double start, stop;  /* emits while start <= t < stop [s]; stop = INFINITY: to the end */
    int bubble;          /* 0: none; k + 1: the particles join bubble k (their fluid->bubble), so gas
                          * blown into a bubble's film belongs to it (docs/film.md, "Blowing") */
} pfsph_emitter_params;

#endif
