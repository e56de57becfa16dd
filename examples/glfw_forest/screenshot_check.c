/*
 * glfw_forest_check — does a glfw_forest screenshot show terrain and trees?
 *
 *   glfw_forest_check FILE.ppm
 *
 * Reads a binary PPM (P6, maxval 255) and sorts its pixels by colour, not by
 * comparing with a reference image (software renderers differ in the last bits):
 *  - tree:    conifer green, dark and saturated: G at least 1.8 × R and B (the
 *             splats are about 2.5 ×; the forest floor under them, which the
 *             terrain shows where no trees are drawn, only 1.3 ×);
 *  - sky:     blue above red and green (the sky, and terrain fogged into it);
 *  - terrain: the rest that is not dark or grey (the HUD's panel and text):
 *             meadow, scrub, rock and snow, whose blue never leads.
 * Passes (exit 0) when terrain covers at least MIN_TERRAIN and trees at least
 * MIN_TREES of the image; prints the shares either way. Exit 1 on failure,
 * 2 on a file it cannot read.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Shares of the image. The test's view shows about 65 % terrain and 0.3-5 % trees:
 * fewer when a slow or busy machine (or a sanitizer build) gets a small budget, and
 * with --morph, whose selections also cover what the camera may see next. Without
 * trees (the greedy solver draws none) the tree share is 0.000, the forest floor
 * included, so 0.1 % (about 900 pixels at 1280 x 720) still tells the two apart. */
#define MIN_TERRAIN 0.20
#define MIN_TREES 0.001

static int read_header_number(FILE *f, int *out) {
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

int main(int argc, char **argv) {
    FILE *f;
    int w = 0, h = 0, maxval = 0;
    unsigned char *px;
    size_t n, i, tree = 0, sky = 0, terrain = 0;
    double share_tree, share_terrain, share_sky;
    if (argc == 2 && (strcmp(argv[1], "--help") == 0 || strcmp(argv[1], "-h") == 0)) {
        printf("usage: glfw_forest_check FILE.ppm\n"
               "\n"
               "Sorts the pixels of a glfw_forest screenshot (binary PPM, maxval 255) into\n"
               "tree, sky and terrain by colour, prints their shares, and passes when\n"
               "terrain covers at least %.0f %% and trees %.1f %% of the image.\n"
               "Exit status 0 when it passes, 1 when it does not, 2 for a file it cannot\n"
               "read or a bad command line.\n",
               100.0 * MIN_TERRAIN, 100.0 * MIN_TREES);
        return 0;
    }
    if (argc != 2) {
        fprintf(stderr, "usage: glfw_forest_check FILE.ppm (--help explains)\n");
        return 2;
    }
    f = fopen(argv[1], "rb");
    if (!f || fgetc(f) != 'P' || fgetc(f) != '6' || !read_header_number(f, &w) ||
        !read_header_number(f, &h) || !read_header_number(f, &maxval) || maxval != 255 || w <= 0 ||
        h <= 0 || w > 16384 || h > 16384 || fgetc(f) == EOF) {
        fprintf(stderr, "glfw_forest_check: %s is not a binary PPM with maxval 255\n", argv[1]);
        if (f)
            fclose(f);
        return 2;
    }
    n = (size_t)w * (size_t)h;
    px = (unsigned char *)malloc(3u * n);
    if (!px || fread(px, 3u, n, f) != n) {
        fprintf(stderr, "glfw_forest_check: %s is truncated\n", argv[1]);
        free(px);
        fclose(f);
        return 2;
    }
    fclose(f);
    for (i = 0; i < n; ++i) {
        int r = px[3u * i], g = px[3u * i + 1u], b = px[3u * i + 2u];
        int hi = r > g ? (r > b ? r : b) : (g > b ? g : b);
        int lo = r < g ? (r < b ? r : b) : (g < b ? g : b);
        if (g >= 24 && g <= 160 && 10 * g >= 18 * r && 10 * g >= 18 * b)
            ++tree;
        else if (b > r && b > g)
            ++sky;
        else if (hi >= 60 && (hi - lo >= 16 || hi >= 200))
            ++terrain;
    }
    free(px);
    share_tree = (double)tree / (double)n;
    share_terrain = (double)terrain / (double)n;
    share_sky = (double)sky / (double)n;
    printf("glfw_forest_check: %dx%d terrain=%.3f trees=%.3f sky=%.3f (need terrain >= %.2f, "
           "trees >= %.3f)\n",
           w, h, share_terrain, share_tree, share_sky, MIN_TERRAIN, MIN_TREES);
    if (share_terrain < MIN_TERRAIN || share_tree < MIN_TREES) {
        printf("glfw_forest_check: FAILED: the screenshot lacks %s\n",
               share_terrain < MIN_TERRAIN ? "terrain" : "trees");
        return 1;
    }
    return 0;
}
