/* libFuzzer target: the JSON scene loader must return OK or a clean error for any bytes. */
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "pfsph/scene.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    char *text = malloc(size + 1);
    if (!text) return 0;
    memcpy(text, data, size);
    text[size] = 0;
    static pfsph_scene s;
    pfsph_error err;
    int rc = pfsph_scene_parse(&s, text, "fuzz.json", &err);
    if (rc != PFSPH_OK && rc != PFSPH_EINPUT) abort(); /* only these two outcomes exist */
    if (rc != PFSPH_OK && !err.msg[0]) abort();        /* an error always says why */
    free(text);
    return 0;
}
