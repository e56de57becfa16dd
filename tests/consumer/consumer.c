/*
 * Uses an installed libtclod the way a host engine would: one object with
 * three discrete levels (a chain) and a terrain patch refined by four
 * sub-patches, a selector, one frame. Checks the version and the budget.
 * Exits 0 on success.
 */
#include <tclod/tclod.h>

#include <stdio.h>

/* Per node: benefit and cost, with diminishing returns down each hierarchy. */
static const double node_benefit[] = {1.0, 1.5, 1.75, 2.0, 0.7, 0.7, 0.7, 0.7};
static const double node_cost[] = {1.0, 2.0, 4.0, 1.0, 0.5, 0.5, 0.5, 0.5};

static double benefit(void *user, const tclod_query *q) {
    (void)user;
    return node_benefit[q->id];
}

static double cost(void *user, const tclod_query *q) {
    (void)user;
    return node_cost[q->id];
}

static int fail(const char *what, tclod_status s) {
    fprintf(stderr, "consumer: %s: %s\n", what, tclod_status_string(s));
    return 1;
}

int main(void) {
    tclod_scene *scene = NULL;
    tclod_selector *sel = NULL;
    tclod_selector_desc desc;
    tclod_frame frame = {NULL, 5.0, 0.0, 0};
    tclod_stats stats;
    const tclod_id *ids = NULL;
    size_t n = 0, i;
    tclod_id id, parent = TCLOD_NONE, terrain;
    double total = 0.0;
    int level, k;
    tclod_status s;

    if (tclod_version() != TCLOD_VERSION_NUMBER) {
        fprintf(stderr, "consumer: header %d, library %u\n", TCLOD_VERSION_NUMBER, tclod_version());
        return 1;
    }

    if ((s = tclod_scene_create(NULL, &scene)) != TCLOD_OK)
        return fail("tclod_scene_create", s);
    for (level = 0; level < 3; ++level) {
        if ((s = tclod_scene_add_node(scene, parent, NULL, &id)) != TCLOD_OK)
            return fail("tclod_scene_add_node", s);
        parent = id;
    }
    if ((s = tclod_scene_add_node(scene, TCLOD_NONE, NULL, &terrain)) != TCLOD_OK)
        return fail("tclod_scene_add_node", s);
    for (k = 0; k < 4; ++k) {
        if ((s = tclod_scene_add_node(scene, terrain, NULL, &id)) != TCLOD_OK)
            return fail("tclod_scene_add_node", s);
    }

    tclod_selector_desc_default(&desc);
    desc.callbacks.benefit = benefit;
    desc.callbacks.cost = cost;
    if ((s = tclod_selector_create(scene, &desc, NULL, &sel)) != TCLOD_OK)
        return fail("tclod_selector_create", s);
    if ((s = tclod_select(sel, &frame, &stats)) != TCLOD_OK)
        return fail("tclod_select", s);
    if ((s = tclod_selector_cut(sel, &ids, &n)) != TCLOD_OK)
        return fail("tclod_selector_cut", s);

    for (i = 0; i < n; ++i) {
        if (ids[i] >= tclod_scene_node_count(scene)) {
            fprintf(stderr, "consumer: cut lists unknown node %u\n", (unsigned)ids[i]);
            return 1;
        }
        total += node_cost[ids[i]];
    }
    if (n == 0 || total > frame.budget || stats.cost > frame.budget) {
        fprintf(stderr, "consumer: %u nodes, cost %g (stats %g), budget %g\n", (unsigned)n, total,
                stats.cost, frame.budget);
        return 1;
    }

    printf("consumer: libtclod %s, %u nodes selected, cost %g of %g\n", tclod_version_string(),
           (unsigned)n, total, frame.budget);
    tclod_selector_destroy(sel);
    tclod_scene_destroy(scene);
    return 0;
}
