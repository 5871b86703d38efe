/* fuzz_replay.c: a main() for the fuzz target without libFuzzer: replays files through it. */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

/* Reads a whole file into a malloc'd buffer; NULL (and a message) on failure. */
static uint8_t *replay_read(const char *path, size_t *size)
{
    FILE *f = fopen(path, "rb");
    if (!f) {
        perror(path);
        return NULL;
    }
    uint8_t *buf = NULL;
    size_t len = 0, cap = 0, n;
    do {
        if (len == cap) {
            uint8_t *p = realloc(buf, cap = cap ? 2 * cap : 4096);
            if (!p) {
                fprintf(stderr, "%s: out of memory\n", path);
                goto fail;
            }
            buf = p;
        }
        n = fread(buf + len, 1, cap - len, f);
        len += n;
    } while (n > 0);
    if (ferror(f)) {
        perror(path);
        goto fail;
    }
    fclose(f);
    *size = len;
    return buf;
fail:
    free(buf);
    fclose(f);
    return NULL;
}

/* Every argument is one input, run as the fuzzer would run it; a crash or sanitizer report
 * ends the process, so exit 0 means every input gave commands or a clean error. */
int main(int argc, char **argv)
{
    if (argc < 2) {
        fprintf(stderr, "usage: fuzz_replay FILE...\n");
        return 2;
    }
    for (int i = 1; i < argc; i++) {
        size_t size;
        uint8_t *data = replay_read(argv[i], &size);
        if (!data)
            return 1;
        LLVMFuzzerTestOneInput(data, size);
        free(data);
    }
    printf("fuzz_replay: %d inputs replayed\n", argc - 1);
    return 0;
}
