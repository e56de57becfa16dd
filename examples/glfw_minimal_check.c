/*
 * glfw_minimal_check — does a glfw_minimal screenshot show its boxes at several
 * levels of detail?
 *
 *   glfw_minimal_check FILE.ppm
 *
 * Reads a binary PPM (P6, maxval 255) and counts the pixels of each level's
 * colour in each of its face shades (glfw_minimal.h), within CLOSE of each
 * channel: a flat colour without lighting is stored as it was given, give or
 * take a renderer's rounding. Passes (exit 0) when the boxes cover at least
 * MIN_BOXES of the image and at least MIN_LEVELS levels cover MIN_LEVEL each:
 * the near boxes finer than the far ones. Prints the shares either way. Exit 1
 * on failure, 2 on a file it cannot read.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "glfw_minimal.h"

/* The headless test's view (frame 30 at 3 ms, 1024 x 640) is 59 % boxes: red
 * 0.8 %, orange 16 %, green 38 %, blue 4 %. A field drawn at one level, or not
 * at all, fails. */
#define MIN_BOXES 0.20
#define MIN_LEVEL 0.01
#define MIN_LEVELS 2
#define CLOSE 2

static int read_number(FILE *f, int *out) {
    int c = fgetc(f);
    while (c == '#' || c == ' ' || c == '\t' || c == '\n' || c == '\r') {
        if (c == '#')
            while (c != '\n' && c != EOF)
                c = fgetc(f);
        c = fgetc(f);
    }
    if (c == EOF || ungetc(c, f) == EOF)
        return 0;
    return fscanf(f, "%d", out) == 1;
}

/* The level whose colour in some shade the pixel has, or -1. */
static int level_of(const unsigned char *px) {
    for (int k = 0; k < GLFW_MINIMAL_LEVELS; ++k)
        for (int s = 0; s < 3; ++s) {
            int c = 0;
            while (c < 3 &&
                   abs(px[c] - glfw_minimal_colour[k][c] * glfw_minimal_shade[s] / 4) <= CLOSE)
                ++c;
            if (c == 3)
                return k;
        }
    return -1;
}

int main(int argc, char **argv) {
    FILE *f;
    int w = 0, h = 0, maxval = 0, levels = 0;
    unsigned char *px;
    size_t n, i, at[GLFW_MINIMAL_LEVELS] = {0}, boxes = 0;
    if (argc == 2 && strcmp(argv[1], "--help") == 0) {
        printf("usage: glfw_minimal_check FILE.ppm\n"
               "\n"
               "Counts the pixels of a glfw_minimal screenshot (binary PPM, maxval 255) in\n"
               "each level's colour, prints their shares, and passes when boxes cover at\n"
               "least %.0f %% of the image and %d levels at least %.0f %% each.\n"
               "Exit status 0 when it passes, 1 when it does not, 2 for a file it cannot\n"
               "read or a bad command line.\n",
               100.0 * MIN_BOXES, MIN_LEVELS, 100.0 * MIN_LEVEL);
        return 0;
    }
    if (argc != 2) {
        fprintf(stderr, "usage: glfw_minimal_check FILE.ppm (--help explains)\n");
        return 2;
    }
    f = fopen(argv[1], "rb");
    if (!f || fgetc(f) != 'P' || fgetc(f) != '6' || !read_number(f, &w) || !read_number(f, &h) ||
        !read_number(f, &maxval) || maxval != 255 || w <= 0 || h <= 0 || w > 16384 || h > 16384 ||
        fgetc(f) == EOF) {
        fprintf(stderr, "glfw_minimal_check: %s is not a binary PPM with maxval 255\n", argv[1]);
        if (f)
            fclose(f);
        return 2;
    }
    n = (size_t)w * (size_t)h;
    px = (unsigned char *)malloc(3u * n);
    if (!px || fread(px, 3u, n, f) != n) {
        fprintf(stderr, "glfw_minimal_check: %s is truncated\n", argv[1]);
        free(px);
        fclose(f);
        return 2;
    }
    fclose(f);
    for (i = 0; i < n; ++i) {
        int k = level_of(px + 3u * i);
        if (k >= 0)
            ++at[k], ++boxes;
    }
    free(px);
    printf("glfw_minimal_check: %dx%d boxes=%.3f levels", w, h, (double)boxes / (double)n);
    for (int k = 0; k < GLFW_MINIMAL_LEVELS; ++k) {
        printf("%c%.3f", k ? '/' : '=', (double)at[k] / (double)n);
        levels += (double)at[k] >= MIN_LEVEL * (double)n;
    }
    printf(" (need boxes >= %.2f, %d levels >= %.2f)\n", MIN_BOXES, MIN_LEVELS, MIN_LEVEL);
    if ((double)boxes < MIN_BOXES * (double)n || levels < MIN_LEVELS) {
        printf("glfw_minimal_check: FAILED: %s\n",
               levels < MIN_LEVELS ? "too few levels" : "too few boxes");
        return 1;
    }
    return 0;
}
