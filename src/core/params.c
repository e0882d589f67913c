/* Defaults of the model's parameters and the closed forms every layer needs (the pair force
 * shape of PF Eq. 6 and its surface-tension constant lambda of Eq. 13). */
#include "pfsph/params.h"

#include <math.h>
#include <string.h>

static const double PI = 3.14159265358979323846;

double pfsph_pairwise_shape(double r, double R)
{
    if (r > R) return 0.0;
    return cos(1.5 * PI * r / R); /* Eq. 6 */
}

double pfsph_pairwise_lambda(int dim, double R)
{
    const double U = 1.5 * PI;
    if (dim == 2) {
        /* sigma = -(n^2/3) int_0^R r^3 F(r) dr with F = s cos(U r / R). */
        return R * R * R * R * (U * U * U - 6.0 * U - 6.0) / (3.0 * U * U * U * U);
    }
    /* sigma = -(pi n^2/8) int_0^R r^4 F(r) dr (NOTES item 6). */
    double U2 = U * U;
    return PI / 8.0 * R * R * R * R * R * (U2 * U2 - 12.0 * U2 + 24.0) / (U2 * U2 * U);
}

/* Measured in 2D (docs/thermostat.md, "Surface tension at temperature"; bench/pf_sigma.c):
 * lattice discs of radius 15 d, sigma target 4 N/m, k 1.7, h = 2 d, nu 1e-3, WCSPH, the
 * interior mechanical pressure averaged over 1-4 s (Laplace: dp = sigma / R). Checked on other
 * radii and with PCISPH by test_pf_laplace. */
static const double sigma_theta[] = {0.005, 0.01, 0.02, 0.04, 0.08};
static const double sigma_ratio[] = {1.0, 1.0, 1.0, 1.0, 1.0};
#define NSIGMA (sizeof sigma_theta / sizeof sigma_theta[0])

double pfsph_pairwise_sigma_factor(int dim, double theta)
{
    /* Thermostat off: a frozen particle solid, whose "tension" depends on how it froze (Laplace
     * slopes of 0.76-0.88 sigma, docs/pairwise.md); Eq. 13 stays the reference. 3D: not
     * calibrated. */
    if (dim != 2 || !(theta > 0)) return 1.0;
    if (theta <= sigma_theta[0]) return sigma_ratio[0];
    for (size_t i = 1; i < NSIGMA; i++)
        if (theta <= sigma_theta[i]) {
            double u = (theta - sigma_theta[i - 1]) / (sigma_theta[i] - sigma_theta[i - 1]);
            return sigma_ratio[i - 1] + u * (sigma_ratio[i] - sigma_ratio[i - 1]);
        }
    return sigma_ratio[NSIGMA - 1]; /* beyond the table: its last value (check warns) */
}

double pfsph_pairwise_sigma_theta_max(void) { return sigma_theta[NSIGMA - 1]; }

void pfsph_pairwise_defaults(pfsph_pairwise_params *p)
{
    memset(p, 0, sizeof(*p));
    p->k = cbrt(80.0 / 30.0); /* Eq. 5 */
    p->filter = true;
    p->eta = 0.2;
    p->eps_min = 0.5;
    p->center = PFSPH_PW_CENTER_PARTICLE; /* Eq. 7 as written */
    pfsph_shift_defaults(&p->shift);
    p->thermo.enabled = true;
    p->thermo.kT = -1;
    p->thermo.reduced = PFSPH_THERMO_REDUCED_DEFAULT;
}

void pfsph_shift_defaults(pfsph_shift_params *p)
{
    p->D = 0;
    p->A = 0;
    p->surface = 0.9;
    p->max_frac = 0.05;
}

void pfsph_diffuse_defaults(pfsph_diffuse_params *p)
{
    memset(p, 0, sizeof(*p));
    p->enabled = false;
    p->max_particles = 1000000;
    p->sampling_rate = 200.0; /* Table 1 "sampling frequency" */
    p->phi_v_min = 2.0;       /* Table 3 */
    p->phi_v_max = 8.0;
    p->phi_e_min = 2.0;
    p->phi_e_max = 8.0;
    p->energy_mass = 0.0;
    p->emit_radius = 0.0;
    p->emit_radius_scale = 1.0;
    p->emit_height_scale = 1.0;
    p->lifetime_min = 0.0;
    p->lifetime_max = 3.0;    /* Tables 1-3 "survival time (max)" */
    p->foam_min_neighbors = -1;
    p->foam_max_neighbors = -1;
    /* Section 4.2: spray k_b = k_cp = 0; foam k_ext = k_b = 0; Section 6.2: k_b = 5.6,
     * k_cp = 0.5, k_t = 0.5 / 1.0 / 0.33. */
    p->type[PFSPH_DIFFUSE_SPRAY] = (pfsph_diffuse_coupling){1.0, 0.0, 0.0, 0.5};
    p->type[PFSPH_DIFFUSE_FOAM] = (pfsph_diffuse_coupling){0.0, 0.0, 0.5, 1.0};
    p->type[PFSPH_DIFFUSE_BUBBLE] = (pfsph_diffuse_coupling){1.0, 5.6, 0.5, 0.33};
}

void pfsph_diffuse_thresholds(const pfsph_diffuse_params *p, int dim, double h, double spacing,
                              int *foam_min, int *foam_max)
{
    /* Fluid neighbours of a point inside a full support: support volume / particle volume. */
    double q = h / spacing;
    double full = dim == 3 ? 4.0 / 3.0 * 3.141592653589793 * q * q * q
                           : 3.141592653589793 * q * q;
    *foam_min = p->foam_min_neighbors >= 0 ? p->foam_min_neighbors : (int)lround(0.2 * full);
    *foam_max = p->foam_max_neighbors >= 0 ? p->foam_max_neighbors
                                           : (int)lround(2.0 / 3.0 * full);
}
