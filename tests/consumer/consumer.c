/*
 * Uses libtclod the way a host engine would: one object with three discrete
 * levels (a chain), a terrain patch refined by four sub-patches and a prop
 * whose cost the host cannot tell (NaN), a selector, one frame. Checks the
 * version, the budget, and that the NaN is counted and its node left out:
 * the library keeps its NaN checks even when the host is built with
 * -ffast-math (.ci/run builds this program so). Exits 0 on success.
 */
#include <tclod/tclod.h>

#include <stdio.h>
#include <stdlib.h>

/* Per node: benefit and cost, with diminishing returns down each hierarchy. */
static const double node_benefit[] = {1.0, 1.5, 1.75, 2.0, 0.7, 0.7, 0.7, 0.7};
static const double node_cost[] = {1.0, 2.0, 4.0, 1.0, 0.5, 0.5, 0.5, 0.5};
/* Node 8, the prop: benefit 1, cost NaN (read at run time, so that no
 * compiler flag can fold it away). */
#define PROP 8u

static double benefit(void *user, const tclod_query *q) {
    (void)user;
    return q->id == PROP ? 1.0 : node_benefit[q->id];
}

static double cost(void *user, const tclod_query *q) {
    (void)user;
    return q->id == PROP ? strtod("nan", NULL) : node_cost[q->id];
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
    tclod_id id, parent = TCLOD_NONE, terrain, prop;
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
    if ((s = tclod_scene_add_node(scene, TCLOD_NONE, NULL, &prop)) != TCLOD_OK || prop != PROP)
        return fail("tclod_scene_add_node", s);

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
        if (ids[i] >= tclod_scene_node_count(scene) || ids[i] == PROP) {
            fprintf(stderr, "consumer: cut lists node %u, unknown or the prop\n", (unsigned)ids[i]);
            return 1;
        }
        total += node_cost[ids[i]];
    }
    if (stats.invalid_values != 1) {
        fprintf(stderr, "consumer: the NaN cost was counted %u times\n",
                (unsigned)stats.invalid_values);
        return 1;
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
