/*
 * TCLOD_SOLVER_ROBIN_HOOD: proportional time distribution, "Robin Hood's
 * algorithm for TCLOD" (seed 003 §5).
 *
 * Every visible instance gets a value (eq. 8-11: its un-projected area over
 * its depth or distance, times its importance). The render time, the frame's
 * budget, is then shared out in proportion to value (eq. 2-4) while the
 * instances are visited from the least to the most complex (complexity: the
 * cost of the finest representation at a reference area, found once per scene
 * change): each takes the finest representation its share affords and hands
 * what it leaves back for the instances after it, so simple objects' surplus
 * reaches complex ones. One pass, no iteration.
 *
 * Instances are chains of single children (an object's levels; the finest
 * affordable level is found by binary search over their monotone costs) and
 * smooth objects (the resolution whose cost matches the share, by a monotone
 * inverse). Where a chain ends in a node with several children (a terrain
 * quadtree, a group impostor) libtclod goes on the same way below it: when the
 * instance's share covers all the children's simplest levels, they become
 * instances of their own, each guaranteed its simplest level and sharing the
 * rest by value, so the cut never has a hole.
 */
#include "internal.h"

#include <math.h>
#include <string.h>

/* The pass keeps this far (relative) inside the budget, so that the drift of
 * the running pool never carries the exact total over it. */
#define BUDGET_MARGIN 1e-9
/* Regula falsi steps of a smooth object's inverse cost. */
#define INVERSE_STEPS 60u

/* ---- value functions (eq. 8-11) ------------------------------------------------- */

double tclod_value_of(tclod_value f, double area, double depth, double distance,
                      double importance) {
    double v;
    if (!(area >= 0.0) || !(depth > 0.0) || !(distance > 0.0) || !(importance >= 0.0) ||
        isinf(area) || isinf(depth) || isinf(distance) || isinf(importance))
        return 0.0;
    switch (f) {
    case TCLOD_VALUE_AREA_SQRT_DEPTH: v = area / sqrt(depth); break;
    case TCLOD_VALUE_AREA_DEPTH: v = area / depth; break;
    case TCLOD_VALUE_AREA_DEPTH2: v = area / (depth * depth); break;
    case TCLOD_VALUE_SQRT_AREA_DISTANCE2: v = sqrt(area) / (distance * distance); break;
    case TCLOD_VALUE_BENEFIT: v = 1.0; break;
    default: return 0.0;
    }
    return v * importance;
}

/* The value of an instance with bounds b (NULL or radius < 0: none) and
 * importance I under this frame's view: a = pi r², z the depth of the centre
 * along the view direction and d its distance, both at least the near plane.
 * Without bounds a = 1; without a view z = d = 1. */
static double instance_value(const tclod_selector *sel, const float *b, double importance) {
    double area = 1.0, depth = 1.0, distance = 1.0;
    if (b && b[3] >= 0.0f) {
        area = 3.14159265358979323846 * (double)b[3] * (double)b[3];
        if (sel->has_view) {
            const tclod_view_cache *c = &sel->view;
            double p[3];
            int k;
            for (k = 0; k < 3; ++k) p[k] = (double)b[k] - c->eye[k];
            depth = p[0] * c->forward[0] + p[1] * c->forward[1] + p[2] * c->forward[2];
            distance = sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
            if (depth < c->near_z) depth = c->near_z;
            if (distance < c->near_z) distance = c->near_z;
        }
    }
    return tclod_value_of(sel->desc.value, area, depth, distance, importance);
}

/* ---- instances and their order (once per scene change) -------------------------- */

static uint32_t child_count(const tclod_scene *s, tclod_id n) {
    return s->child_first[n + 1u] - s->child_first[n];
}

static int is_head(const tclod_scene *s, tclod_id n) {
    return s->parent[n] == TCLOD_NONE || child_count(s, s->parent[n]) > 1u;
}

static int value_bad(double v) { return !(v >= 0.0) || isinf(v); }

/* A sanitised complexity: NaN, infinite or negative (or, when it is a smooth
 * cost, with such a slope) counts as the most complex (visited last) and is
 * counted like any bad callback value. */
static double complexity_value(tclod_selector *sel, double c, double slope) {
    if (!value_bad(c) && !value_bad(slope)) return c;
    sel->stats.invalid_values++;
    if (sel->desc.strict) sel->failed = 1;
    return value_bad(c) ? HUGE_VAL : c;
}

/* The complexity of the instance starting at node head (chain end `end`) or
 * of smooth object `smooth` at sorted position pos: the host's complexity
 * callback, or the cost of the finest representation at the reference area
 * with no view. */
static double node_complexity(tclod_selector *sel, tclod_id head, tclod_id end) {
    const tclod_callbacks *cb = &sel->desc.callbacks;
    tclod_query q;
    q.count = 1;
    q.view = NULL;
    q.screen_area = (float)sel->desc.reference_area;
    q.distance = -1.0f;
    q.members = NULL;
    q.id = cb->complexity ? head : end;
    q.bounds = sel->scene->bounds[4u * q.id + 3u] >= 0.0f ? &sel->scene->bounds[4u * q.id] : NULL;
    return complexity_value(sel, cb->complexity ? cb->complexity(cb->user, &q)
                                                : cb->cost(cb->user, &q), 0.0);
}

static double smooth_complexity(tclod_selector *sel, uint32_t pos) {
    const tclod_callbacks *cb = &sel->desc.callbacks;
    const tclod_scene *s = sel->scene;
    tclod_query q;
    double c, d;
    q.id = s->smooth_order[pos];
    q.count = 1;
    q.view = NULL;
    q.screen_area = (float)sel->desc.reference_area;
    q.distance = -1.0f;
    q.members = s->smooth_order + pos;
    q.bounds = &s->smooth_bounds[4u * q.id];
    if (cb->complexity) return complexity_value(sel, cb->complexity(cb->user, &q), 0.0);
    d = 0.0;
    c = cb->smooth_cost(cb->user, &q, 1.0, &d);
    return complexity_value(sel, c, d);
}

/* Whether smooth objects are instances: the smooth callbacks are set. */
static int with_smooth(const tclod_selector *sel) {
    return sel->desc.callbacks.smooth_benefit && sel->desc.callbacks.smooth_cost;
}

/* The chains (every node belongs to the chain of the nearest instance start
 * above it), each branching node's children and the top-level instances, in
 * order of complexity. Smooth objects are identified by their position in the
 * scene's smooth order, plus the node count. */
static void prepare(tclod_selector *sel) {
    const tclod_scene *s = sel->scene;
    uint32_t n = s->node_count, used = 0, i, count = 0;
    double *keys;
    tclod_id id;
    for (id = 0; id < n; ++id) {
        tclod_id m;
        if (!is_head(s, id)) continue;
        sel->rh_chain_at[id] = used;
        for (m = id;; m = s->children[s->child_first[m]]) {
            sel->rh_chain[used++] = m;
            if (child_count(s, m) != 1u) break;
        }
        sel->rh_chain_len[id] = used - sel->rh_chain_at[id];
        sel->rh_key[id] = node_complexity(sel, id, m);
    }
    assert(used == n);
    /* each branch's children, least complex first (ties: smaller id) */
    for (id = 0; id < n; ++id) {
        uint32_t first = s->child_first[id], k = child_count(s, id), j;
        if (k < 2u) continue;
        for (j = 0; j < k; ++j) {
            sel->rh_child[first + j] = s->children[first + j];
            sel->scratch_key[first + j] = -sel->rh_key[s->children[first + j]];
        }
        tclod_sort_by_key(sel->rh_child + first, sel->scratch_key + first, k);
    }
    /* the second half of rh_key holds the order's keys */
    keys = sel->rh_key + sel->rh_cap;
    for (i = 0; i < s->root_count; ++i) {
        sel->rh_order[count] = s->roots[i];
        keys[count++] = -sel->rh_key[s->roots[i]];
    }
    if (with_smooth(sel))
        for (i = 0; i < s->smooth_count; ++i) {
            sel->rh_order[count] = n + i;
            keys[count++] = -smooth_complexity(sel, i);
        }
    tclod_sort_by_key(sel->rh_order, keys, count);
    sel->rh_order_count = count;
    sel->rh_version = s->version;
}

/* ---- the pass -------------------------------------------------------------------- */

static void cut_add(tclod_selector *sel, tclod_id n, uint8_t flags) {
    sel->node[n].cut_pos = sel->cut_count;
    sel->cut[sel->cut_count++] = n;
    sel->flags[n] = flags;
}

static void cut_clear(tclod_selector *sel) {
    uint32_t i;
    for (i = 0; i < sel->cut_count; ++i) {
        sel->node[sel->cut[i]].cut_pos = TCLOD_NONE;
        sel->flags[sel->cut[i]] = 0;
    }
    sel->cut_count = 0;
}

static int visible(const tclod_selector *sel, tclod_id n) { return sel->node[n].benefit > 0.0; }

/* The finest level of head's chain whose cost is at most `time`, by binary
 * search over the chain's costs (which grow level by level); TCLOD_NONE when
 * not even the first fits. Returns -1 on a strict error. */
static int finest_level(tclod_selector *sel, tclod_id head, double time, tclod_id *out) {
    const tclod_id *chain = sel->rh_chain + sel->rh_chain_at[head];
    uint32_t lo = 0, hi = sel->rh_chain_len[head];
    *out = TCLOD_NONE;
    if (tclod_evaluate_node(sel, chain[0]) != 0) return -1;
    if (!(sel->node[chain[0]].cost <= time)) return 0;
    while (hi - lo > 1u) { /* chain[lo] fits; chain[hi] does not, or is past the end */
        uint32_t mid = lo + (hi - lo) / 2u;
        if (tclod_evaluate_node(sel, chain[mid]) != 0) return -1;
        if (sel->node[chain[mid]].cost <= time)
            lo = mid;
        else
            hi = mid;
    }
    *out = chain[lo];
    return 0;
}

/* The children of branching node b: evaluated, their simplest levels' summed
 * cost in *reserve and their values in *value (invisible children: none).
 * Returns -1 on a strict error. */
static int branch_children(tclod_selector *sel, tclod_id b, double *reserve, double *value) {
    const tclod_scene *s = sel->scene;
    uint32_t j, first = s->child_first[b], k = child_count(s, b);
    *reserve = *value = 0.0;
    for (j = 0; j < k; ++j) {
        tclod_id c = s->children[first + j];
        if (tclod_evaluate_node(sel, c) != 0) return -1;
        if (!visible(sel, c)) continue;
        *reserve += sel->node[c].cost;
        *value += instance_value(sel, &s->bounds[4u * c], sel->node[c].benefit);
    }
    return 0;
}

/* Places the instance starting at visible node `head` with `time` (which
 * covers its first level) and, below it, the instances of every branch its
 * share reaches, depth first with an explicit stack. Returns the time used in
 * *used; -1 on a strict error. */
static int place_node(tclod_selector *sel, tclod_id head, double time, double *used) {
    const tclod_scene *s = sel->scene;
    tclod_rh_frame *stack = sel->rh_stack;
    uint32_t top = 0;
    double base = 0.0; /* the cost of head's first level, as its branch counts it */
    for (;;) {
        tclod_id level, end = sel->rh_chain[sel->rh_chain_at[head] + sel->rh_chain_len[head] - 1u];
        double reserve, value;
        int refine = 0;
        if (finest_level(sel, head, time, &level) != 0) return -1;
        assert(level != TCLOD_NONE);
        sel->stats.iterations++;
        if (level == end && child_count(s, end) > 1u) {
            if (branch_children(sel, end, &reserve, &value) != 0) return -1;
            refine = isfinite(reserve) && reserve <= time;
        }
        if (refine) { /* the children become instances sharing this one's time */
            tclod_rh_frame *f = &stack[top++];
            f->branch = end;
            f->next = 0;
            f->extra = time - reserve;
            f->value_left = value;
            f->alloc = time;
            f->base = base;
        } else {
            double u = sel->node[level].cost;
            cut_add(sel, level, 0);
            if (top == 0) {
                *used = u;
                return 0;
            }
            stack[top - 1u].extra -= u - base;
        }
        /* the next child to place, closing the branches that are done */
        for (;;) {
            tclod_rh_frame *f = &stack[top - 1u];
            if (f->next < child_count(s, f->branch)) {
                tclod_id c = sel->rh_child[s->child_first[f->branch] + f->next++];
                double v, share;
                if (!visible(sel, c)) {
                    cut_add(sel, c, 0); /* culled: in the cut, not drawn */
                    continue;
                }
                v = instance_value(sel, &s->bounds[4u * c], sel->node[c].benefit);
                share = f->value_left > 0.0 ? v * f->extra / f->value_left : 0.0;
                share = share > f->extra ? f->extra : (share > 0.0 ? share : 0.0);
                f->value_left -= v;
                head = c;
                base = sel->node[c].cost;
                time = base + share;
                break;
            } else {
                double u = f->alloc - f->extra, b = f->base;
                if (--top == 0) {
                    *used = u;
                    return 0;
                }
                stack[top - 1u].extra -= u - b;
            }
        }
    }
}

/* The smooth object at sorted position pos: culled like the mixed solver's,
 * its importance the benefit at full resolution. Writes its bounds' projected
 * area and distance. Returns the value (0: not drawn), or -1 on a strict
 * error. */
static double smooth_value(tclod_selector *sel, uint32_t pos, float *area, float *distance) {
    const float *b = &sel->scene->smooth_bounds[4u * sel->scene->smooth_order[pos]];
    double importance, db;
    *area = *distance = -1.0f;
    if (sel->has_view) {
        tclod_view_cache_measure(&sel->view, b, area, distance);
        if (!(*area > 0.0f) || (double)*area < sel->desc.smooth_cull_area) return 0.0;
    }
    tclod_smooth_call(sel, pos, 1, NULL, *area, *distance, 1.0, &importance, &db, NULL, NULL);
    if (sel->failed) return -1.0;
    return importance > 0.0 ? instance_value(sel, b, importance) : 0.0;
}

/* The resolution of smooth object pos whose cost is `time` (the largest that
 * fits, the cost growing with the resolution): regula falsi with the Illinois
 * correction, keeping the lower end within `time`. Returns it (0 when not even
 * the smallest fits) with its cost in *cost; -1 on a strict error. */
static double smooth_resolution(tclod_selector *sel, uint32_t pos, float area, float distance,
                                double time, double *cost) {
    double lo = TCLOD_SLOPE_FLOOR, hi = 1.0, clo, chi, dc;
    int side = 0;
    uint32_t k;
    *cost = 0.0;
    tclod_smooth_call(sel, pos, 1, NULL, area, distance, 1.0, NULL, NULL, &chi, &dc);
    if (sel->failed) return -1.0;
    if (chi <= time) {
        *cost = chi;
        return 1.0;
    }
    tclod_smooth_call(sel, pos, 1, NULL, area, distance, lo, NULL, NULL, &clo, &dc);
    if (sel->failed) return -1.0;
    if (!(clo <= time)) return 0.0;
    for (k = 0; k < INVERSE_STEPS && hi - lo > 1e-12 && clo < time * (1.0 - 1e-9); ++k) {
        double x = isfinite(chi) ? lo + (hi - lo) * (time - clo) / (chi - clo) : 0.5 * (lo + hi);
        double c;
        if (!(x > lo && x < hi)) x = 0.5 * (lo + hi);
        tclod_smooth_call(sel, pos, 1, NULL, area, distance, x, NULL, NULL, &c, &dc);
        if (sel->failed) return -1.0;
        if (c <= time) {
            lo = x;
            clo = c;
            if (side < 0) chi = time + 0.5 * (chi - time);
            side = -1;
        } else {
            hi = x;
            chi = c;
            if (side > 0) clo = time - 0.5 * (time - clo);
            side = 1;
        }
    }
    /* the Illinois correction moved the bracket's values: ask the cost of lo */
    tclod_smooth_call(sel, pos, 1, NULL, area, distance, lo, NULL, NULL, cost, &dc);
    if (sel->failed) return -1.0;
    return *cost <= time ? lo : 0.0;
}

/* Draws smooth object pos at resolution r as a group of one. */
static int add_group(tclod_selector *sel, uint32_t pos, float area, float distance, double r,
                     double cost) {
    tclod_vars *V = &sel->vars;
    const float *b = &sel->scene->smooth_bounds[4u * sel->scene->smooth_order[pos]];
    uint32_t v = pos; /* variables sit at their position: groups come out in order */
    double db;
    V->r[v] = r;
    V->area[v] = area;
    V->distance[v] = distance;
    memcpy(&V->bounds[4u * v], b, 4 * sizeof(float));
    tclod_smooth_call(sel, pos, 1, NULL, area, distance, r, &V->b[v], &db, NULL, NULL);
    V->c[v] = cost;
    return sel->failed ? -1 : 0;
}

/* The exact total in result order; should the pool's drift ever carry it
 * over the budget, smooth objects go first, then the cut is repaired as the
 * greedy repairs its own. */
static int finish(tclod_selector *sel) {
    double sum = 0.0;
    uint32_t i;
    for (i = 0; i < sel->cut_count; ++i) {
        tclod_id n = sel->cut[i];
        if (visible(sel, n) && !(sel->flags[n] & TCLOD_FLAG_DROPPED)) sum += sel->node[n].cost;
    }
    sel->cost_sum = sum;
    for (i = 0; i < sel->vars.count; ++i) sum += sel->vars.c[i];
    if (!isinf(sum) && sum <= sel->frame->budget) return 0;
    sel->vars.count = 0;
    return tclod_greedy_enforce(sel);
}

/* Cycle 1 of §5.2: the value of every instance (0: not drawn) into rh_key,
 * and their total. */
static int values(tclod_selector *sel, double *total) {
    const tclod_scene *s = sel->scene;
    uint32_t k;
    *total = 0.0;
    for (k = 0; k < sel->rh_order_count; ++k) {
        uint32_t id = sel->rh_order[k];
        double v;
        if (id < s->node_count) {
            if (tclod_evaluate_node(sel, id) != 0) return -1;
            v = visible(sel, id) ? instance_value(sel, &s->bounds[4u * id], sel->node[id].benefit)
                                 : 0.0;
        } else {
            float area, distance;
            v = smooth_value(sel, id - s->node_count, &area, &distance);
            if (v < 0.0) return -1;
        }
        sel->rh_key[k] = v;
        *total += v;
    }
    return 0;
}

/* One variable per smooth object, at its position in the smooth order, all
 * at resolution 0 (not drawn) until the object's share comes. */
static void empty_variables(tclod_selector *sel) {
    tclod_vars *V = &sel->vars;
    uint32_t i;
    V->count = with_smooth(sel) ? sel->scene->smooth_count : 0u;
    for (i = 0; i < V->count; ++i) {
        V->first[i] = i;
        V->size[i] = 1;
        V->r[i] = V->b[i] = V->c[i] = 0.0;
    }
}

/* Cycle 1 and the start of cycle 2. Returns 0 or -1 (strict error). */
static int robin_hood_start(tclod_selector *sel) {
    tclod_resume *R = &sel->resume;
    double budget = sel->frame->budget, total;
    if (sel->rh_version != sel->scene->version) {
        prepare(sel);
        if (sel->failed) {
            sel->rh_version = 0; /* strict: ask again next time */
            return -1;
        }
    }
    cut_clear(sel);
    empty_variables(sel);
    sel->reserved = 0.0;
    if (values(sel, &total) != 0) return -1;
    R->pool = isinf(budget) ? budget : budget - BUDGET_MARGIN * budget;
    R->value_left = total;
    R->limited = 0;
    R->k = 0;
    return 0;
}

/* Cycle 2: least complex first, each share v_i t_r / v_f of what is left
 * (eq. 2-4), what an instance leaves going on to the next. Once the search
 * is stopped, the instances left get their simplest level while it fits.
 * Returns 0 (also when the step's slice ran out) or -1 (strict error). */
static int share_out(tclod_selector *sel) {
    const tclod_scene *s = sel->scene;
    tclod_resume *R = &sel->resume;
    for (; R->k < sel->rh_order_count; ++R->k) {
        uint32_t id = sel->rh_order[R->k];
        double v = sel->rh_key[R->k], share, used = 0.0;
        int stopped;
        if (!sel->stopped && tclod_out_of_time(sel) && sel->paused) return 0;
        stopped = sel->stopped;
        share = R->value_left > 0.0 && !stopped
                    ? (isinf(R->pool) ? R->pool : v * R->pool / R->value_left)
                    : 0.0;
        if (share > R->pool) share = R->pool;
        R->value_left -= v;
        if (id < s->node_count) {
            if (!visible(sel, id)) {
                cut_add(sel, id, 0);
                continue;
            }
            if (sel->node[id].cost <= share) {
                if (place_node(sel, id, share, &used) != 0) return -1;
            } else if ((sel->desc.misfit == TCLOD_MISFIT_COARSEST || stopped) &&
                       sel->node[id].cost <= R->pool) {
                cut_add(sel, id, 0);
                used = sel->node[id].cost;
                R->limited = 1;
            } else {
                cut_add(sel, id, TCLOD_FLAG_DROPPED);
                sel->stats.dropped_roots++;
                R->limited = 1;
            }
        } else if (v > 0.0) {
            uint32_t pos = id - s->node_count;
            float area, distance;
            double r, cost;
            sel->stats.variables++;
            sel->stats.iterations++;
            /* the culling and importance were worked out in cycle 1; the
             * measures are cheap and the callbacks cached nothing */
            if (sel->has_view)
                tclod_view_cache_measure(&sel->view, &s->smooth_bounds[4u * s->smooth_order[pos]],
                                         &area, &distance);
            else
                area = distance = -1.0f;
            r = smooth_resolution(sel, pos, area, distance, share, &cost);
            if (r < 0.0) return -1;
            if (r == 0.0 && sel->desc.misfit == TCLOD_MISFIT_COARSEST) {
                tclod_smooth_call(sel, pos, 1, NULL, area, distance, TCLOD_SLOPE_FLOOR, NULL, NULL,
                                  &cost, &r);
                r = cost <= R->pool ? TCLOD_SLOPE_FLOOR : 0.0;
            }
            if (r < 1.0) R->limited = 1;
            if (r > 0.0) {
                if (add_group(sel, pos, area, distance, r, cost) != 0) return -1;
                used = cost;
            }
        }
        R->pool -= used;
        if (R->pool < 0.0) R->pool = 0.0;
    }
    return 0;
}

tclod_status tclod_robin_hood_solve(tclod_selector *sel) {
    tclod_resume *R = &sel->resume;
    int rc = 0;
    if (R->phase == 0) {
        rc = robin_hood_start(sel);
        R->phase = 1;
    }
    if (rc == 0) rc = share_out(sel);
    if (rc == 0 && sel->paused) return TCLOD_OK;
    if (rc == 0) rc = finish(sel);
    tclod_greedy_end(sel);
    if (rc != 0) return TCLOD_ERR_CALLBACK;
    if (!sel->stopped) sel->stats.stop_reason = R->limited ? TCLOD_STOP_BUDGET : TCLOD_STOP_FINEST;
    return sel->failed ? TCLOD_ERR_CALLBACK : TCLOD_OK;
}
