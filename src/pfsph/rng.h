/* Counter-based random numbers (Philox-4x32-10, Salmon et al., SC 2011): a pure function of
 * (seed, particle id, step, stream), so a draw never depends on thread count, loop order or
 * how many draws other particles made. No state to carry, save or share between threads. */
#ifndef PFSPH_RNG_H
#define PFSPH_RNG_H

#include <stdint.h>

/* Four independent 32-bit words for the key (seed) and the counter (id, step, stream). The
 * 128-bit counter is {id, step low 32 bits, step high 32 bits, stream}; the 64-bit key is the
 * seed. Distinct (seed, id, step, stream) give statistically independent blocks. */
void pfsph_rng_u32x4(uint64_t seed, uint32_t id, uint64_t step, uint32_t stream, uint32_t out[4]);

/* Four uniform doubles in [0, 1) (32 random bits each, exact multiples of 2^-32). */
void pfsph_rng_uniform4(uint64_t seed, uint32_t id, uint64_t step, uint32_t stream, double out[4]);

/* Map a 32-bit word to [0, 1). */
static inline double pfsph_rng_to_unit(uint32_t u) { return (double)u * (1.0 / 4294967296.0); }

#endif
