/* Thermostat of the pair-force liquid: pairwise random forces that are the fluctuation partner
 * of the SPH viscosity (smoothed DPD, Espanol & Revenga 2003), symmetric and deterministic
 * (a counter-based hash of seed, the two ids and the step). docs/thermostat.md. */
#ifndef PFSPH_THERMOSTAT_H
#define PFSPH_THERMOSTAT_H

#include <math.h>
#include <stdint.h>

#include "pfsph/ctx.h"

/* Salt of fluid-solid pairs, so that fluid id a with boundary id b draws a number unrelated to
 * the fluid pair (a, b). */
#define PFSPH_THERMO_SALT_WALL 0x5bd1e9955bd1e995ull

static inline uint64_t pfsph__mix64(uint64_t z)
{
    /* splitmix64's finaliser (Steele, Lea, Flood 2014): a bijection with full avalanche */
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}

/* The per-step key: every pair of this step draws from mix(key ^ pair). */
static inline uint64_t pfsph_thermo_step_key(uint64_t seed, uint64_t step, uint64_t salt)
{
    return pfsph__mix64(pfsph__mix64(seed + 0x9E3779B97F4A7C15ull) ^ (step * 0xD1B54A32D192ED03ull + salt));
}

/* (double) u for u < 2^53, exactly, in operations that vectorise without a 64-bit integer
 * conversion instruction (AVX2 and AVX-512F lack one): u / 2 through the 2^52 exponent trick,
 * doubled, plus the low bit. */
static inline double pfsph__u53_double(uint64_t u)
{
    const uint64_t b = 0x4330000000000000ull | (u >> 1);
    double d;
    __builtin_memcpy(&d, &b, sizeof d);
    return (d - 4503599627370496.0) * 2.0 + ((u & 1) ? 1.0 : 0.0);
}

/* theta_ab = theta_ba, uniform on [-sqrt 3, sqrt 3] (zero mean, unit variance), as Groot &
 * Warren 1997 draw it. */
static inline double pfsph_thermo_theta(uint64_t key, uint32_t a, uint32_t b)
{
    uint64_t lo = a < b ? a : b, hi = a < b ? b : a;
    uint64_t z = pfsph__mix64(key ^ pfsph__mix64((lo << 32) | hi));
    return 1.7320508075688772 * ((double)(z >> 11) * (2.0 / 9007199254740992.0) - 1.0);
}

/* The resolved temperature in use (0: off). */
static inline double pfsph_thermostat_kT(const pfsph_ctx *ctx)
{
    const pfsph_pairwise_params *pp = ctx->pairwise;
    return pp && pp->enabled && pp->thermo.enabled ? pp->thermo.kT_resolved : 0.0;
}

/* 2 kT visc_c / dt with visc_c = 2 (d + 2), the Morris viscosity's constant: the noise of a pair
 * is sqrt(amp * kT-factor * Gamma / visc_c) (0 without a temperature or a step). */
static inline double pfsph__thermo_amp(const pfsph_ctx *ctx)
{
    const double kT = pfsph_thermostat_kT(ctx);
    return kT > 0 && ctx->dt > 0 ? 2.0 * kT / ctx->dt * (double)(2 * (ctx->dim + 2)) : 0.0;
}

/* Phase a's temperature relative to kT: rho_a / rho_ref (the liquid kT was set for), so that
 * every phase has the same thermal speed; at equal kT a gas 10-1000x lighter would move
 * 3-32x faster than its liquid and leave its bubble. Solids and unknown densities: 1. */
static inline double pfsph_thermostat_scale(const pfsph_ctx *ctx, int a)
{
    const double rr = ctx->pairwise->thermo.rho_ref, ra = (double)ctx->rest_density[a];
    return rr > 0 && ra > 0 && ctx->phases[a].kind != PFSPH_PHASE_SOLID ? ra / rr : 1.0;
}

/* The noise force of one fluid pair divided by r (multiply by x_ij): amp_ts = 2 kT_ij visc_c /
 * dt, nu the pair's viscosity, dwr = W'(r)/r (negative), theta the pair's draw. The
 * viscosity's friction is m_i / n_j on i and m_j / n_i on j; one force on both takes their
 * harmonic mean 2 m_i m_j / (m_i n_i + m_j n_j): the same from either side, the arithmetic
 * mean to second order within a phase, and no more than twice the lighter particle's friction
 * across a density ratio (the arithmetic mean shook a gas particle next to water with the
 * water's friction, 500x its own at a ratio of 1000). */
static inline double pfsph__thermo_fluid(double amp_ts, double nu, double mi, double mj, double ndi, double ndj,
                                         double r2, double dwr, double eps, double rr, double theta)
{
    double g = nu * 2.0 * mi * mj / (mi * ndi + mj * ndj) * r2 * -dwr / (r2 + eps);
    return g > 0 ? sqrt(amp_ts * g) * theta / rr : 0.0;
}

/* The same for a fluid particle of mass m_i and a solid particle of volume V_b whose wall
 * friction viscosity is nu_w (Akinci: m_i visc_c nu_w V_b r^2 |W'/r| / (r^2 + eps)). */
static inline double pfsph__thermo_wall(double amp_ts, double nuw, double mi, double vb, double r2, double dwr,
                                        double eps, double rr, double theta)
{
    double g = nuw * mi * vb * r2 * -dwr / (r2 + eps);
    return g > 0 ? sqrt(amp_ts * g) * theta / rr : 0.0;
}

/* ADD the random pair forces of this step (dt = ctx->dt) to ctx->ax, ay, az, as accelerations,
 * and store them alone in noise[0..2] (the time step must not follow them):
 * F_ij = sqrt(2 kT_ij Gamma_ij / dt) theta_ij e_ij (kT_ij: the colder phase's), where Gamma_ij is the friction coefficient of
 * the Morris viscosity between i and j (fluid pairs: the harmonic mean of its i -> j and j -> i
 * values, so that Gamma_ij = Gamma_ji) and of the Akinci wall friction between i and a solid particle. Needs
 * ctx->nd of this step. Deterministic for any thread count; sum over fluid pairs zero to
 * round-off. */
void pfsph_thermostat_apply(const pfsph_ctx *ctx, pfsph_real *const noise[3]);

/* Kinetic temperature of the fluid: sum m_i |v_i - v_cm|^2 / (dim (N - 1)) [J]; 0 if N < 2. */
double pfsph_thermostat_measure(const pfsph_particles *f, const pfsph_real *mass, int dim);
/* Its two sequential sums over [lo, hi), continuing those of the particles before lo: acc =
 * {sum m, sum m vx, sum m vy, sum m vz}, then e += sum m |v - vc|^2 (returned); vc = P / M. */
void pfsph__thermostat_moments(const pfsph_particles *f, const pfsph_real *mass, size_t lo, size_t hi, double acc[4]);
double pfsph__thermostat_spread(const pfsph_particles *f, const pfsph_real *mass, int dim, size_t lo, size_t hi,
                                const double vc[3], double e);

#endif
