/* libFuzzer target: the checkpoint reader must reject any damaged buffer cleanly and never
 * touch the simulation unless the buffer is whole. */
#include <stdint.h>
#include <stdlib.h>

#include "pfsph/checkpoint.h"
#include "pfsph/scene.h"
#include "pfsph/sim.h"

static const char *SCENE =
    "{\"dimension\": 2, \"particle_radius\": 0.01, \"gravity\": [0, -9.81],"
    " \"domain\": {\"min\": [-0.05, -0.05], \"max\": [0.45, 0.45]},"
    " \"phases\": [{\"name\": \"water\"}, {\"name\": \"wall\", \"kind\": \"solid\"}],"
    " \"fluid\": [{\"shape\": \"box\", \"min\": [0, 0], \"max\": [0.1, 0.1], \"phase\": \"water\"}],"
    " \"solids\": [{\"shape\": \"container\", \"min\": [0, 0], \"max\": [0.4, 0.4], \"phase\": \"wall\"}]}";

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    static pfsph_sim *sim;
    static pfsph_scene s;
    pfsph_error err;
    if (!sim) {
        if (pfsph_scene_parse(&s, SCENE, "fuzz", &err) || pfsph_sim_create(&sim, &s, &err)) abort();
    }
    int rc = pfsph_checkpoint_decode(sim, data, size, "fuzz.bin", NULL, &err);
    if (rc != PFSPH_OK && rc != PFSPH_EINPUT && rc != PFSPH_ENOMEM) abort();
    return 0;
}
