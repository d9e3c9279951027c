/*
 * Replays a trajectory through flapssm's streaming predictor, as a flight computer would:
 * the model and the stream are created once, then each input sample is stepped with no
 * allocation.
 *
 *   replay MODEL.json INPUTS.csv [--particles P] [--seed S] [--f32 | --f32-native] [--repeat R]
 *
 * INPUTS.csv: a header line, then one row of D_u numbers per time step, in the model's input
 * order and units (the wing: AoA rad, |v| m/s, a_x a_y a_z m/s^2, pitch rate rad/s, pitch
 * acceleration rad/s^2). Writes `step,mean_0..,var_0..` rows to stdout (%.17g), like
 * `flapssm predict --inputs`, and the time per step and the stream's size to stderr.
 * --f32: float inputs and outputs on the double-precision stream (flapssm_stream_step_f32_arrays);
 * --f32-native: the single-precision stream (flapssm_single_stream_*).
 * --repeat R replays the trajectory R times (reset between replays) for a steadier timing;
 * only the first replay is printed.
 *
 * Build (after `cargo build --release -p flapssm-capi`):
 *   cc -O2 -std=c11 -I crates/capi/include examples/c/replay.c \
 *      target/release/libflapssm_c.a -lm -lpthread -ldl -o replay
 */
#define _POSIX_C_SOURCE 199309L
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "flapssm.h"

#define MAX_COLUMNS 64

static int fail(const char *what) {
    fprintf(stderr, "replay: %s: %s\n", what, flapssm_last_error());
    return 1;
}

/* Reads the rows of `path` after its header into a new array of rows * n values. */
static double *read_inputs(const char *path, size_t n, size_t *rows) {
    FILE *f = fopen(path, "r");
    if (!f) {
        perror(path);
        return NULL;
    }
    size_t cap = 1024, len = 0;
    double *data = malloc(cap * n * sizeof *data);
    char line[4096];
    int header = 1;
    size_t line_no = 0;
    while (data && fgets(line, sizeof line, f)) {
        line_no++;
        if (header) {
            header = 0;
            continue;
        }
        if (line[0] == '\n' || line[0] == '\0') continue;
        if (len == cap) {
            cap *= 2;
            double *grown = realloc(data, cap * n * sizeof *data);
            if (!grown) break;
            data = grown;
        }
        char *p = line;
        for (size_t j = 0; j < n; j++) {
            char *end;
            data[len * n + j] = strtod(p, &end);
            if (end == p) {
                fprintf(stderr, "%s: line %zu: column %zu is not a number\n", path, line_no, j + 1);
                free(data);
                fclose(f);
                return NULL;
            }
            p = (*end == ',') ? end + 1 : end;
        }
        len++;
    }
    fclose(f);
    *rows = len;
    return data;
}

static double seconds(void) {
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

int main(int argc, char **argv) {
    if (argc < 3) {
        fprintf(stderr, "usage: replay MODEL.json INPUTS.csv [--particles P] [--seed S] [--f32 | --f32-native] [--repeat R]\n");
        return 2;
    }
    size_t particles = 30;
    unsigned long long seed = 0;
    int single = 0; /* 1: float I/O on the double stream; 2: the single-precision stream */
    long repeat = 1;
    for (int i = 3; i < argc; i++) {
        if (!strcmp(argv[i], "--particles") && i + 1 < argc) particles = strtoul(argv[++i], NULL, 10);
        else if (!strcmp(argv[i], "--seed") && i + 1 < argc) seed = strtoull(argv[++i], NULL, 10);
        else if (!strcmp(argv[i], "--repeat") && i + 1 < argc) repeat = strtol(argv[++i], NULL, 10);
        else if (!strcmp(argv[i], "--f32")) single = 1;
        else if (!strcmp(argv[i], "--f32-native")) single = 2;
        else {
            fprintf(stderr, "replay: unknown argument %s\n", argv[i]);
            return 2;
        }
    }

    FlapssmModel *model = NULL;
    FlapssmStream *stream = NULL;
    FlapssmSingleStream *stream32 = NULL;
    if (flapssm_model_load(argv[1], &model) != FLAPSSM_STATUS_OK) return fail("loading the model");
    size_t du = flapssm_model_n_input(model), dy = flapssm_model_n_output(model);
    if (du > MAX_COLUMNS || dy > MAX_COLUMNS) {
        fprintf(stderr, "replay: model too wide\n");
        return 1;
    }
    if (single == 2) {
        if (flapssm_single_stream_new(model, particles, seed, &stream32) != FLAPSSM_STATUS_OK)
            return fail("creating the stream");
    } else if (flapssm_stream_new(model, particles, seed, &stream) != FLAPSSM_STATUS_OK) {
        return fail("creating the stream");
    }
    flapssm_model_free(model);

    size_t rows = 0;
    double *u = read_inputs(argv[2], du, &rows);
    if (!u) return 1;
    float u32[MAX_COLUMNS], mean32[MAX_COLUMNS], var32[MAX_COLUMNS];
    double mean[MAX_COLUMNS], var[MAX_COLUMNS];

    printf("step");
    for (size_t d = 0; d < dy; d++) printf(",mean_%zu", d);
    for (size_t d = 0; d < dy; d++) printf(",var_%zu", d);
    printf("\n");

    double t0 = seconds();
    for (long r = 0; r < repeat; r++) {
        if (r > 0) {
            FlapssmStatus reset = single == 2 ? flapssm_single_stream_reset(stream32) : flapssm_stream_reset(stream);
            if (reset != FLAPSSM_STATUS_OK) return fail("reset");
        }
        for (size_t t = 0; t < rows; t++) {
            const double *ut = u + t * du;
            FlapssmStatus status;
            if (single) {
                for (size_t j = 0; j < du; j++) u32[j] = (float)ut[j];
                status = single == 2 ? flapssm_single_stream_step(stream32, u32, du, mean32, var32, dy)
                                     : flapssm_stream_step_f32_arrays(stream, u32, du, mean32, var32, dy);
                for (size_t d = 0; d < dy; d++) {
                    mean[d] = mean32[d];
                    var[d] = var32[d];
                }
            } else {
                status = flapssm_stream_step(stream, ut, du, mean, var, dy);
            }
            if (status != FLAPSSM_STATUS_OK) return fail("step");
            if (r > 0) continue;
            printf("%zu", t);
            for (size_t d = 0; d < dy; d++) printf(",%.17g", mean[d]);
            for (size_t d = 0; d < dy; d++) printf(",%.17g", var[d]);
            printf("\n");
        }
    }
    double per_step = (seconds() - t0) / ((double)rows * (double)repeat);
    fprintf(stderr, "replay: %zu steps x %ld, %zu particles, %s: %.2f us per step (printing included in the first replay)\n",
            rows, repeat, particles, single == 2 ? "f32 native" : single ? "f32 I/O" : "f64", 1e6 * per_step);

    flapssm_stream_free(stream);
    flapssm_single_stream_free(stream32);
    free(u);
    return 0;
}
