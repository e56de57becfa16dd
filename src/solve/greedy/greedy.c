/*
 * TCLOD_SOLVER_GREEDY: the Mason–Blake increment over LOD hierarchies
 * ([MB97], as summarised in [GEO §3.1–3.2] and [ZMK02 §2.1.1]).
 *
 * A selection is a cut through the hierarchies. An increment replaces a cut
 * node by its children; increments are taken best Δbenefit/Δcost first from an
 * indexed heap, and one that does not fit is skipped while smaller ones are
 * still tried (fill). A cold solve starts from the roots and, because plain
 * ratio order can be arbitrarily bad, finally compares its result with the best
 * skipped increment taken alone (with the increments above it), which keeps it
 * within half of the optimum when benefits show diminishing returns. The
 * increments keyed above the previous cold solve's first misfit, the heap's
 * first pops, are taken without ordering them when they surely fit
 * (take_closure). With lookahead an increment may replace its node by the
 * best-ratio cut of its subtree a few levels deep (Dinkelbach's method over
 * the subtree's dynamic program, lookahead_key), for benefits whose returns
 * do not diminish. When even the roots do not fit, refinements that cost
 * less than what they replace (children out of view cost nothing) come
 * before roots are left out (shed_cost). A warm solve starts from the
 * previous cut: it re-evaluates only the frontier (cut nodes, their children
 * and their collapsible parents), first takes the collapses a cold solve
 * would have made (free ones, into invisible parents, those that gain),
 * applies decrements (children -> parent, least benefit lost per cost saved
 * first) while over budget, then increments and increment/decrement swaps
 * while they gain, past [MB97]'s balance point too where a misfit lacks less
 * than its cost (exchange_may_gain); on a scene with nodes that are not
 * resident it first gives up the cut nodes residency no longer allows
 * (stream_repair).
 * A final exact re-summation in result order repairs any rounding drift, so the
 * budget guarantee holds to the last bit.
 *
 * This file holds the papers' loop (fill, swaps, the closure) and the final
 * repair; the starts, cold and warm, are in greedy_start.c, the lookahead in
 * greedy_lookahead.c, the passes after the plain cold one (T(n) and the
 * restarts' search) in greedy_search.c, and the cut with its increments and
 * decrements, which all four share, in greedy_internal.h. The four are one
 * unit: the other solvers and the selector call only greedy.h's functions.
 *
 * Layer: solve, which may call core, eval and solve. Calls: core (alloc.c,
 * heap.c, view.c); eval (evaluate.c); solve (greedy_lookahead.c,
 * greedy_search.c, greedy_start.c).
 */
#include "greedy_internal.h"

#include <float.h>
#include <math.h>
#include <string.h>

/* ---- for greedy_lookahead.c -------------------------------------------------- */

void tclod_greedy_enqueue_looking(tclod_selector *sel, tclod_id n, double key, int append) {
    enqueue_as(sel, n, key, append, 1);
}

void tclod_greedy_rekey_looking(tclod_selector *sel, tclod_id n, tclod_id *held, double key) {
    rekey_as(sel, n, held, key, 1);
}

double tclod_greedy_increment_key(tclod_selector *sel, tclod_id n, int *failed) {
    return increment_key(sel, n, failed);
}

void tclod_greedy_cut_add(tclod_selector *sel, tclod_id n) {
    greedy_cut_add(sel, n);
}

int tclod_greedy_requeue(tclod_selector *sel, tclod_id n, tclod_id *held) {
    return requeue_increment(sel, n, held);
}

int tclod_greedy_queue_decrement(tclod_selector *sel, tclod_id p) {
    return queue_decrement(sel, p, 0);
}

/* ---- the search ------------------------------------------------------------------ */

/* Restores feasibility of a warm start: decrements while over budget (by the
 * running sum, or by its compensated total while decrements are left).
 * Returns 1 when no decrement that saves cost is left and the cut is still
 * over: the solve then starts cold, where refinements that save cost come
 * before roots are left out (tclod_greedy_start_cold). Always completes. */
static int restore_budget(tclod_selector *sel) {
    while (!greedy_feasible(sel) || (sel->greedy.dec.count > 0 &&
                                     !tclod_within(sel, sel->cost_sum, greedy_cut_budget(sel)))) {
        if (sel->greedy.dec.count == 0 || sel->greedy.dec.items[0].key == -HUGE_VAL)
            return greedy_feasible(sel) ? 0 : 1;
        sel->stats.iterations++;
        if (apply_decrement(sel, tclod_heap_pop(&sel->greedy.dec)) != 0)
            return -1;
    }
    return 0;
}

/* Loss per saved cost of the cheapest decrement that saves cost, or +inf. */
static double min_loss_ratio(const tclod_selector *sel) {
    if (sel->greedy.dec.count == 0)
        return HUGE_VAL;
    tclod_id p = sel->greedy.dec.items[0].id;
    if (!(sel->greedy.delta[p].delta_c > 0.0))
        return HUGE_VAL;
    return -sel->greedy.dec.items[0].key;
}

/* Past the balance point (the best increment's ratio not above the cheapest
 * decrement's, r_min), a swap can still gain: freeing `need` loses at least
 * r_min * need, and a misfit that lacks less than its cost, need < Δc, gains
 * more than that when Δb > r_min * need, that is when its ratio is above
 * r_min * (1 - room / Δc), room being what the budget has left. Equal-cost
 * exchanges cannot gain there; these fill the room a misfit leaves over. 1
 * while such a swap may gain for the best increment n: the increments that
 * come later have no better ratio, and none costs less than the cheapest
 * queued, so once r(n) <= r_min * (1 - room / c_min) none can. At most
 * GREEDY_EXCHANGES are tried a solve, which bounds the work past the
 * balance point. */
static int exchange_may_gain(tclod_selector *sel) {
    tclod_greedy_resume *R = &sel->resume.greedy;
    double r_min = min_loss_ratio(sel), room, c_min;
    if (R->exchanges >= GREEDY_EXCHANGES || !(r_min < HUGE_VAL) || sel->unaffordable)
        return 0;
    room = greedy_cut_budget(sel) - sel->cost_sum - sel->cost_err;
    if (!(room > 0.0))
        return 0;
    if (sel->greedy.cheap_live != CHEAP_LIVE || sel->greedy.cheap.count == 0)
        return 1;
    c_min = -sel->greedy.cheap.items[0].key;
    return c_min > 0.0 && sel->greedy.inc.items[0].key > r_min * (1.0 - room / c_min);
}

/* After decrement p is taken for a swap: the collapse of p's parent q, when
 * q's other children are in the cut, is queued too (a chain collapses level
 * by level), unless q is n's parent. A swap that fails takes these out again
 * (untake_parents). */
static int take_parent_too(tclod_selector *sel, tclod_id p, tclod_id n_parent) {
    tclod_id q = sel->scene->parent[p];
    uint32_t count, i;
    const tclod_id *ch;
    if (q == TCLOD_NONE || q == n_parent || tclod_heap_contains(&sel->greedy.dec, q))
        return 0;
    ch = children_of(sel, q, &count);
    for (i = 0; i < count; ++i)
        if (ch[i] != p && sel->node[ch[i]].cut_pos == TCLOD_NONE)
            return 0;
    return queue_collapsible(sel, q, 0);
}

/* A failed swap's decrements taken (scratch[0 .. taken)) leave the cut as it
 * was: their parents, queued by take_parent_too (and taken, maybe, then put
 * back), are not collapsible and go. */
static void untake_parents(tclod_selector *sel, uint32_t taken) {
    uint32_t i;
    for (i = 0; i < taken; ++i) {
        tclod_id q = sel->scene->parent[sel->scratch[i]];
        if (q != TCLOD_NONE && tclod_heap_contains(&sel->greedy.dec, q) && !collapsible(sel, q))
            tclod_heap_remove(&sel->greedy.dec, q);
    }
}

/* Makes room for increment n (with collapse, for the collapse into n, out of
 * the decrement heap, that gains: tclod_greedy_take_first_collapses) by decrements whose
 * summed loss stays below its gain, least loss per saved cost first. A taken
 * decrement makes its parent's collapse a candidate when the parent's other
 * children are in the cut (take_parent_too). Returns 1 when the swap was
 * made, 0 when it would not gain. */
static int try_swap(tclod_selector *sel, tclod_id n, int collapse, int *failed) {
    double sign = collapse ? -1.0 : 1.0;
    double need = sel->cost_sum + sign * sel->greedy.delta[n].delta_c - sel->frame->budget;
    double gain = sign * sel->greedy.delta[n].delta_b, freed = 0.0, loss = 0.0;
    tclod_id parent = collapse ? TCLOD_NONE : sel->scene->parent[n];
    uint32_t taken = 0, i;
    int ok = 0;
    if (sel->cost_err > 0.0) /* what the running sum absorbed needs room too */
        need += sel->cost_err;
    *failed = 0;
    /* decrements come least loss per saved cost first, so freeing `need`
     * loses at least that ratio times need */
    if (gain <= min_loss_ratio(sel) * need)
        return 0;
    while (sel->greedy.dec.count > 0) {
        double key = sel->greedy.dec.items[0].key;
        tclod_id p = sel->greedy.dec.items[0].id;
        if (p != parent && !(sel->greedy.delta[p].delta_c > 0.0))
            break; /* the rest saves nothing */
        tclod_heap_pop(&sel->greedy.dec);
        sel->scratch[taken] = p;
        sel->scratch_key[taken] = key;
        taken++;
        if (p == parent)
            continue; /* would remove n itself */
        freed += sel->greedy.delta[p].delta_c;
        loss += sel->greedy.delta[p].delta_b;
        if (gain - loss <= GREEDY_SWAP_MARGIN * fabs(gain))
            break;
        if (freed >= need) {
            ok = 1;
            break;
        }
        if (take_parent_too(sel, p, parent) != 0) {
            *failed = 1;
            break;
        }
    }
    for (i = 0; i < taken; ++i) {
        tclod_id p = sel->scratch[i];
        if (!ok || p == parent)
            tclod_heap_push(&sel->greedy.dec, p, sel->scratch_key[i]);
    }
    if (!ok) {
        untake_parents(sel, taken);
        return 0;
    }
    for (i = 0; i < taken; ++i) {
        tclod_id p = sel->scratch[i];
        if (p == parent)
            continue;
        sel->stats.iterations++;
        if (apply_decrement(sel, p) != 0) {
            *failed = 1;
            return 0;
        }
    }
    if ((collapse ? apply_decrement(sel, n) : apply_increment(sel, n, 1)) != 0)
        *failed = 1;
    return 1;
}

/* 1 when the collapse into p, queued, is free (no loss, no extra cost), into
 * an invisible p, or removes an unaffordable child (decrement_key's first
 * ones). */
static int free_collapse(const tclod_selector *sel, tclod_id p) {
    return tclod_heap_contains(&sel->greedy.dec, p) &&
           sel->greedy.dec.items[sel->greedy.dec.pos[p]].key == HUGE_VAL;
}

/* 1 when the collapse into p, queued, gains benefit at a cost: p is worth more
 * than its children in the cut, typically children that left the frustum
 * while p is still in it. A cold solve never refines such a p (its increment
 * gains nothing), and the decrements' order, which puts collapses that save
 * nothing last, would never undo it. */
static int gaining_collapse(const tclod_selector *sel, tclod_id p) {
    const tclod_delta *d = &sel->greedy.delta[p];
    return tclod_heap_contains(&sel->greedy.dec, p) && d->delta_c < 0.0 &&
           d->delta_b < -GREEDY_SWAP_MARGIN * sel->node[p].benefit;
}

/* Benefit gained per cost added by the gaining collapse into p. */
static double gain_ratio(const tclod_selector *sel, tclod_id p) {
    const tclod_delta *d = &sel->greedy.delta[p];
    return d->delta_b / d->delta_c; /* both < 0 */
}

/* A warm start's first moves, before the budget is restored: the free
 * collapses, and those that gain where they fit or a swap makes room for
 * them (try_swap), cascading up to the parents that become such. Only here
 * and in the last fill (fill_gaining_collapses): in the increments and swaps
 * between, a collapse that gains at a cost is a trade among others (a
 * lookahead's jump may take cheaper children at a loss). The pending ones
 * wait at the top of scratch, below any parked misfits (none at a warm
 * start), as try_swap uses its bottom. */
int tclod_greedy_take_first_collapses(tclod_selector *sel) {
    uint32_t i, n = 0;
    for (i = 0; i < sel->greedy.dec.count; ++i) {
        tclod_id p = sel->greedy.dec.items[i].id;
        if (free_collapse(sel, p) || gaining_collapse(sel, p))
            sel->scratch[sel->cap - ++n] = p;
    }
    while (n > 0) {
        tclod_id p = sel->scratch[sel->cap - n--], up = sel->scene->parent[p];
        int failed = 0;
        if (free_collapse(sel, p) ||
            (gaining_collapse(sel, p) &&
             tclod_within(sel, sel->cost_sum - sel->greedy.delta[p].delta_c,
                          greedy_cut_budget(sel)))) {
            sel->stats.iterations++;
            if (apply_decrement(sel, p) != 0)
                return -1;
        } else if (gaining_collapse(sel, p)) {
            uint32_t slot = sel->greedy.dec.pos[p];
            double key = sel->greedy.dec.items[slot].key;
            sel->stats.iterations++;
            tclod_heap_remove(&sel->greedy.dec, p);
            if (!try_swap(sel, p, 1, &failed))
                tclod_heap_push(&sel->greedy.dec, p, key);
            if (failed)
                return -1;
        } else {
            continue;
        }
        if (up != TCLOD_NONE && (free_collapse(sel, up) || gaining_collapse(sel, up)))
            sel->scratch[sel->cap - ++n] = up;
    }
    return 0;
}

/* A warm solve's last fill: the gaining collapses still queued, best ratio
 * first, each one that fits. */
static int fill_gaining_collapses(tclod_selector *sel) {
    uint32_t i, n = 0;
    for (i = 0; i < sel->greedy.dec.count; ++i) {
        tclod_id p = sel->greedy.dec.items[i].id;
        if (gaining_collapse(sel, p)) {
            sel->scratch[n] = p;
            sel->scratch_key[n++] = gain_ratio(sel, p);
        }
    }
    tclod_sort_by_key(sel->scratch, sel->scratch_key, n);
    for (i = 0; i < n; ++i) {
        tclod_id p = sel->scratch[i];
        if (!gaining_collapse(sel, p) ||
            !tclod_within(sel, sel->cost_sum - sel->greedy.delta[p].delta_c,
                          greedy_cut_budget(sel)))
            continue;
        sel->stats.iterations++;
        if (apply_decrement(sel, p) != 0)
            return -1;
    }
    return 0;
}

/* Relative margin above the previous solve's first misfit from which the
 * plain cold pass takes increments without ordering them. */
#define CLOSURE_MARGIN 1.25

/* The plain cold pass takes the increments keyed at or above closure_key and
 * those they lead to with such keys (the closure) before any other, in the
 * order they were queued, not by key (first in, first out: on large scenes
 * faster than last in, first out, docs/greedy.md). The heap would take the
 * same set first, and if the closure's cost grows by at most the budget left
 * none of its prefixes misfits, so the cut after it is the heap's after as
 * many increments. If the closure does not fit that way the pass starts over
 * with the heap alone. Takes one increment when the solve runs in slices (a
 * slice may end after any), else all of them; ends the closure when none is
 * left. */
static int take_closure(tclod_selector *sel) {
    tclod_resume *R = &sel->resume;
    int sliced = sel->slice_end > 0.0 || sel->slice_iterations != 0;
    uint32_t dropped;
    while (R->greedy.closure_tail > R->greedy.closure_head) {
        tclod_id n = sel->scratch[R->greedy.closure_head];
        double grow = sel->greedy.delta[n].delta_c > 0.0 ? sel->greedy.delta[n].delta_c : 0.0;
        double total = R->greedy.closure_cost + grow;
        if (sel->unaffordable != 0 || !(total <= greedy_cut_budget(sel)) ||
            total + R->greedy.closure_err > greedy_cut_budget(sel))
            break;
        R->greedy.closure_head++;
        tclod_add_compensated(&R->greedy.closure_cost, &R->greedy.closure_err, grow);
        sel->stats.iterations++;
        if (apply_increment_cold(sel, n) != 0)
            return -1;
        if (sliced)
            return 0;
    }
    if (R->greedy.closure_tail == R->greedy.closure_head) {
        R->greedy.closing = 0;
        tclod_heap_build(&sel->greedy.inc);
        return 0;
    }
    R->greedy.closing = 0;
    R->greedy.closure_head = R->greedy.closure_tail = 0;
    dropped = sel->stats.dropped_roots; /* the roots are dropped again, the same way */
    if (tclod_greedy_start_cold(sel) != 0)
        return -1;
    sel->stats.dropped_roots = dropped;
    return 0;
}

/* A warm solve's phases in improve (sel->resume.greedy.phase): the fill,
 * which parks the misfits it skips; the swaps, with every misfit queued again
 * and no skipping (an increment that fits is taken, the best one that does
 * not is swapped in or dropped); then a last fill for the room the swaps left,
 * which drops what it skips. */
enum { PHASE_FILL = 0, PHASE_SWAPS = 1, PHASE_LAST_FILL = 2 };

/* Increments while any fits, best ratio first, skipping those that do not fit
 * (fill). Then a warm solve makes swaps while the best increment's ratio beats
 * the cheapest decrement's (Mason–Blake's balance), and a cold solve records
 * the skipped increments as alternatives. Warm solves also take free
 * collapses first. Stops early at a limit. */
static int improve(tclod_selector *sel, int warm, int alt) {
    tclod_greedy_resume *R = &sel->resume.greedy;
    int *skipped = &sel->resume.skipped, failed = 0;
    uint32_t i;
    for (;;) {
        tclod_id n;
        int swapped;
        if (tclod_out_of_time(sel))
            return 0;
        if (R->closing) {
            if (take_closure(sel) != 0)
                return -1;
            continue;
        }
        if (warm && sel->greedy.dec.count > 0 && sel->greedy.dec.items[0].key == HUGE_VAL) {
            sel->stats.iterations++;
            if (apply_decrement(sel, tclod_heap_pop(&sel->greedy.dec)) != 0)
                return -1;
            continue;
        }
        if (sel->greedy.inc.count == 0 && R->parked == 0)
            break;
        if (sel->greedy.inc.count > 0) {
            n = sel->greedy.inc.items[0].id;
            if (R->left_out > 0 && greedy_left_out(&sel->resume, n)) {
                pop_increment(sel);
                continue;
            }
            if (greedy_increment_fits(sel, n)) { /* its entry goes in apply_increment */
                sel->stats.iterations++;
                if (apply_increment(sel, n, warm) != 0)
                    return -1;
                continue;
            }
            if (!warm)
                greedy_note_misfit(sel, n);
            if (R->phase != PHASE_SWAPS && increment_may_fit(sel)) {
                /* fill: skip the misfit, try smaller ones */
                *skipped = 1;
                if (alt)
                    greedy_consider_alternative(sel, n);
                if (warm && R->phase == PHASE_FILL &&
                    !(sel->flags[n] & (TCLOD_FLAG_JUMP | TCLOD_FLAG_REFIT)))
                    park_misfit(sel, n);
                else
                    skip_misfit(sel, n);
                continue;
            }
            *skipped = 1;
        }
        if (R->parked > 0) { /* the fill ended: the swaps see every misfit */
            unpark_misfits(sel);
            R->phase = PHASE_SWAPS;
            continue;
        }
        if (!warm || R->phase == PHASE_LAST_FILL) {
            if (R->phase != PHASE_SWAPS)
                break;
            R->phase = PHASE_LAST_FILL;
            continue;
        }
        if (!(sel->greedy.inc.items[0].key > min_loss_ratio(sel))) {
            if (!exchange_may_gain(sel)) {
                R->phase = PHASE_LAST_FILL;
                continue;
            }
            R->exchanges++;
        }
        n = pop_increment(sel);
        sel->stats.iterations++;
        swapped = try_swap(sel, n, 0, &failed);
        if (failed)
            return -1;
        if (swapped)
            continue;
    }
    if (alt)
        for (i = 0; i < sel->greedy.inc.count; ++i)
            greedy_consider_alternative(sel, sel->greedy.inc.items[i].id);
    if (warm && fill_gaining_collapses(sel) != 0)
        return -1;
    sel->stats.stop_reason = *skipped ? TCLOD_STOP_BUDGET : TCLOD_STOP_FINEST;
    return 0;
}

/* The cut's total as the budget guarantee sums it: the costs of its visible,
 * kept nodes in result order (docs/api.md); +inf with an unaffordable one. */
static double result_total(const tclod_selector *sel) {
    const tclod_id *cut = sel->cut;
    double sum = 0.0;
    uint32_t i, count = sel->cut_count;
    for (i = 0; i < count; ++i) {
        if (i + TCLOD_CUT_AHEAD < count) /* as the commit reads them */
            TCLOD_PREFETCH(&sel->node[cut[i + TCLOD_CUT_AHEAD]]);
        if (greedy_counts(sel, cut[i]))
            sum += sel->node[cut[i]].cost;
    }
    return sum;
}

/* Whether the frame's time limit or the step's slice has run out: the repair
 * then undoes what its estimate asks for in one round (TCLOD_STOP_TIME when it
 * is the frame's limit). */
static int repair_late(tclod_selector *sel) {
    const tclod_frame *f = sel->frame;
    double now;
    if (sel->stats.stop_reason == TCLOD_STOP_TIME)
        return 1;
    if (!(f->solve_seconds > 0.0) && !(sel->slice_end > 0.0))
        return 0;
    now = tclod_now();
    if (f->solve_seconds > 0.0 && sel->elapsed + (now - sel->start_time) >= f->solve_seconds) {
        if (!sel->stats.over_budget)
            sel->stats.stop_reason = TCLOD_STOP_TIME;
        sel->stopped = 1;
        return 1;
    }
    return sel->slice_end > 0.0 && now >= sel->slice_end;
}

/* The counted nodes of the cut in scratch[0 .. count), in the order the
 * repair leaves them out: lowest value (benefit / cost) first, ties larger id
 * first (stored complemented, so that the sort's ties by smaller id put them
 * so). Returns count. */
static uint32_t drop_order(tclod_selector *sel) {
    uint32_t i, n = 0;
    for (i = 0; i < sel->cut_count; ++i) {
        tclod_id r = sel->cut[i];
        double c;
        if (!greedy_counts(sel, r))
            continue;
        /* with no decrement queued the cut holds roots only: below a refined
         * node, its deepest refined descendant would be collapsible, and the
         * decrement heap holds every collapsible parent of the cut */
        assert(sel->scene->parent[r] == TCLOD_NONE);
        c = sel->node[r].cost;
        sel->scratch[n] = ~r;
        sel->scratch_key[n] = -(c > 0.0 ? sel->node[r].benefit / c : HUGE_VAL);
        n++;
    }
    tclod_sort_by_key(sel->scratch, sel->scratch_key, n);
    return n;
}

/* Brings the total in result order (result_total) within the budget when
 * rounding carried it over (the order of the final sum, or costs the running
 * sums absorbed): decrements, the cheapest first, and once none is left the
 * lowest-value roots left out, one at a time in that order, until the total
 * fits. Summing again after every step would be O(n) per step; instead each
 * round takes the steps an estimate asks for (the last total less the exact
 * cost each step saves), at most 2^r in round r (from 0) and at least half
 * that from round 2 on, and then sums again. A total the estimate gets right
 * is done in the round after the one that found it over; any total in about
 * 2 log2(k) rounds for k steps: O(n log k + k log n) for a cut of n nodes.
 * Roots are left out only after a sum that the decrements could not bring
 * within the budget. Once the frame's time limit (TCLOD_STOP_TIME) or the
 * step's slice has run out, a round takes all the steps the estimate asks for.
 * Always ends within the budget. */
static int enforce_budget(tclod_selector *sel, int dec_built) {
    const tclod_scene *s = sel->scene;
    double limit = greedy_cut_budget(sel), sum = result_total(sel);
    uint32_t round = 0, drops = 0, next_drop = 0, i;
    int dropping = 0, late = 0;
    for (;;) {
        uint32_t most, least, undone = 0;
        double est = sum;
        /* an unaffordable node makes the sum infinite: never within budget */
        if (!isinf(sum) && sum <= limit) {
            sel->cost_sum = sum;
            sel->cost_err = 0.0;
            sel->stats.over_budget = 0; /* the roots' running sum had rounded up */
            return 0;
        }
        if (sel->stats.over_budget)
            return 0; /* the roots alone exceed the budget, and overflow draws them */
        if (!dec_built) {
            tclod_heap_clear(&sel->greedy.dec);
            for (i = 0; i < sel->cut_count; ++i) {
                tclod_id p = s->parent[sel->cut[i]];
                if (queue_decrement(sel, p, 0) != 0)
                    return -1;
            }
            dec_built = 1;
        }
        late = late || repair_late(sel);
        most = late || round > 30u ? UINT32_MAX : 1u << round;
        least = round < 2u ? 1u : 1u << (round > 31u ? 30u : round - 1u);
        while (undone < least || (undone < most && !(est <= limit))) {
            if (sel->greedy.dec.count > 0) {
                tclod_id p = tclod_heap_pop(&sel->greedy.dec);
                est -= sel->greedy.delta[p].delta_c; /* the cost the collapse saves */
                if (apply_decrement(sel, p) != 0)
                    return -1;
            } else {
                tclod_id r;
                if (!dropping) {
                    if (undone > 0)
                        break; /* sum again before leaving out any root */
                    drops = drop_order(sel);
                    dropping = 1;
                }
                if (next_drop == drops)
                    break;
                r = ~sel->scratch[next_drop++];
                est -= sel->node[r].cost;
                account(sel, r, -1.0);
                sel->flags[r] |= TCLOD_FLAG_DROPPED;
                sel->stats.dropped_roots++;
            }
            if (++undone % TCLOD_CLOCK_STRIDE == 0 && !late && repair_late(sel)) {
                late = 1;
                most = UINT32_MAX;
            }
        }
        /* nothing is left to undo: no node is counted, and the total is 0 */
        assert(undone > 0);
        if (undone == 0)
            return 0;
        sum = result_total(sel);
        round++;
    }
}

/* Starts the solve: a warm start is brought within the budget, a cold one
 * starts from the roots. Always completes. */
static int greedy_start(tclod_selector *sel) {
    tclod_resume *R = &sel->resume;
    R->greedy.warm = !sel->desc.cold_start && sel->has_cut && R->greedy.audit != 2;
    R->greedy.fell_back = R->greedy.warm && sel->greedy.fallback.left > 0;
    if (R->greedy.fell_back) {
        R->greedy.warm = 0;
        sel->stats.notes |= TCLOD_NOTE_COLD_FALLBACK;
    }
    R->skipped = 0;
    if (R->greedy.warm && sel->greedy.fallback.since_audit >= TCLOD_AUDIT_PERIOD &&
        sel->desc.solver == TCLOD_SOLVER_GREEDY && sel->desc.greedy.fallback != TCLOD_OFF &&
        sel->desc.greedy.lookahead == 0 && sel->frame->max_iterations == 0 &&
        sel->frame->solve_seconds == 0.0 && !tclod_scene_streams(sel->scene)) {
        R->greedy.audit = 1;
        sel->greedy.fallback.since_audit = 0;
    }
    if (R->greedy.warm && sel->node_version != sel->scene->node_version) {
        /* the edits since the cut was made, from the log while it holds them */
        const tclod_scene *s = sel->scene;
        uint64_t seen = sel->user.log_seen;
        if (seen >= s->log_base && seen <= s->log_base + s->log_count)
            tclod_greedy_repair_from_log(sel, (uint32_t)(seen - s->log_base));
        else
            tclod_greedy_repair_cut(sel);
    }
    if (R->greedy.warm) {
        int rc = tclod_greedy_start_warm(sel);
        if (rc == 0)
            rc = restore_budget(sel);
        if (rc <= 0)
            return rc;
        R->greedy.warm = 0; /* nothing left to collapse fits: start from the roots */
        R->greedy.audit = 0;
    }
    R->greedy.closure_head = R->greedy.closure_tail = 0;
    R->greedy.closing = sel->greedy.closure_hint > 0.0 && sel->frame->max_iterations == 0 &&
                        sel->frame->solve_seconds == 0.0;
    R->greedy.closure_key = sel->greedy.closure_hint * CLOSURE_MARGIN;
    if (tclod_greedy_start_cold(sel) != 0)
        return -1;
    R->greedy.closure_cost = sel->cost_sum;
    R->greedy.closure_err = sel->cost_err;
    tclod_greedy_track(sel); /* the safeguard's state, from the roots' sums */
    R->greedy.misfit = TCLOD_NONE;
    R->greedy.lp_bound = 0.0;
    R->greedy.picks = R->greedy.best_picks = R->greedy.left_out = R->greedy.tries = 0;
    R->greedy.searching = 0;
    return 0;
}

/* After a solve: whether the next one starts warm (docs/greedy.md, falling
 * back). Warm solves keep a running mean of their work (weight 1/8 for the
 * newest); once it exceeds the last cold solve's by TCLOD_FALLBACK_MARGIN,
 * the next span of solves (1, doubling up to TCLOD_FALLBACK_SPAN_MAX while
 * warm starts keep losing) starts from the roots and the mean starts again
 * after them. A mean within the margin resets the span. Not with
 * tclod_greedy_desc.fallback TCLOD_OFF. */
static void weigh_start(tclod_selector *sel) {
    tclod_fallback *fb = &sel->greedy.fallback;
    const tclod_resume *R = &sel->resume;
    double work = (double)sel->stats.evaluations + (double)sel->stats.iterations;
    if (!R->greedy.warm) {
        fb->cold_work = work;
        if (R->greedy.fell_back && fb->left > 0)
            fb->left--;
        return;
    }
    fb->since_audit++;
    fb->warm_work = fb->warm_work > 0.0 ? fb->warm_work + (work - fb->warm_work) / 8.0 : work;
    if (fb->cold_work > 0.0 && fb->warm_work > TCLOD_FALLBACK_MARGIN * fb->cold_work &&
        sel->desc.greedy.fallback != TCLOD_OFF) {
        fb->span = fb->span == 0
                       ? 1u
                       : (fb->span < TCLOD_FALLBACK_SPAN_MAX / 2u ? 2u * fb->span
                                                                  : TCLOD_FALLBACK_SPAN_MAX);
        fb->left = fb->span;
        fb->warm_work = 0.0;
    } else {
        fb->span = 0;
    }
}

/* The audit (docs/greedy.md, warm start). A warm start improves the previous
 * cut one increment, decrement or swap at a time, and can stay in a selection
 * a cold solve beats: where the benefit of a node above the cut grew past what
 * its refined subtree gives, no single decrement shows it. Every
 * TCLOD_AUDIT_PERIOD warm solves without limits, the warm solve's cut is set
 * aside and a cold solve follows; the cold one is kept (and the solve says it
 * fell back) when it has more benefit, else the warm cut is put back. Audits
 * thus bound how long a warm start stays behind. */

/* After an audited warm solve: sets its cut aside and starts the cold one.
 * Returns 0 when there is nothing to compare (roots dropped, over budget). */
static int audit_begin(tclod_selector *sel) {
    tclod_resume *R = &sel->resume;
    if (sel->stats.dropped_roots || sel->stats.over_budget) {
        R->greedy.audit = 0;
        return 0;
    }
    memcpy(sel->greedy.audit_cut, sel->cut, sizeof(tclod_id) * sel->cut_count);
    memset(&R->greedy, 0, sizeof R->greedy); /* the cold solve starts afresh */
    R->greedy.audit_count = sel->cut_count;
    R->greedy.audit_benefit = sel->benefit_sum;
    R->greedy.audit_stop = sel->stats.stop_reason;
    R->greedy.audit = 2;
    R->skipped = 0;
    R->phase = GREEDY_START;
    return 1;
}

/* After the audit's cold solve: keeps the better cut. */
static void audit_end(tclod_selector *sel) {
    tclod_resume *R = &sel->resume;
    uint32_t i;
    if (sel->stats.dropped_roots || sel->stats.over_budget ||
        !(sel->benefit_sum > R->greedy.audit_benefit)) { /* the warm cut stays */
        tclod_greedy_clear_cut(sel);
        sel->cut_count = R->greedy.audit_count;
        memcpy(sel->cut, sel->greedy.audit_cut, sizeof(tclod_id) * sel->cut_count);
        for (i = 0; i < sel->cut_count; ++i) {
            sel->node[sel->cut[i]].cut_pos = i;
            account(sel, sel->cut[i], 1.0);
        }
        sel->stats.stop_reason = R->greedy.audit_stop;
        sel->stats.dropped_roots = 0; /* the warm solve's, as audit_begin found them */
        sel->stats.over_budget = 0;
    } else {
        sel->stats.notes |= TCLOD_NOTE_COLD_FALLBACK;
    }
    R->greedy.audit = 0;
}

tclod_status tclod_greedy_solve(tclod_selector *sel) {
    tclod_resume *R = &sel->resume;
    int rc = 0;
    while (rc == 0 && !sel->paused) {
        switch (R->phase) {
        case GREEDY_START:
            rc = greedy_start(sel);
            R->phase = GREEDY_IMPROVE;
            break;
        case GREEDY_IMPROVE:
            rc = improve(sel, R->greedy.warm, !R->greedy.warm && R->greedy.use_alt);
            if (!sel->paused)
                R->phase = R->greedy.warm ? GREEDY_END : tclod_greedy_after_pass(sel);
            break;
        case GREEDY_PASS:
            R->greedy.tries++;
            rc = tclod_greedy_start_decided(sel);
            R->phase = GREEDY_IMPROVE_PASS;
            break;
        case GREEDY_IMPROVE_PASS:
            if (!R->greedy.infeasible)
                rc = improve(sel, 0, 0);
            if (!sel->paused)
                R->phase = tclod_greedy_after_pass(sel);
            break;
        case GREEDY_REPLAY:
            R->greedy.picks = R->greedy.best_picks;
            memcpy(R->greedy.pick, R->greedy.best_pick, sizeof(tclod_id) * R->greedy.picks);
            memcpy(R->greedy.take, R->greedy.best_take, R->greedy.picks);
            rc = tclod_greedy_start_decided(sel);
            R->phase = GREEDY_IMPROVE_REPLAY;
            break;
        case GREEDY_IMPROVE_REPLAY:
            rc = improve(sel, 0, 0);
            if (!sel->paused)
                R->phase = GREEDY_END;
            break;
        default:
            rc = enforce_budget(sel, R->greedy.warm);
            clear_heaps(sel);
            if (rc != 0)
                return TCLOD_ERR_CALLBACK;
            if (R->greedy.audit == 2) {
                audit_end(sel);
                return TCLOD_OK;
            }
            weigh_start(sel);
            if (R->greedy.audit == 1 && audit_begin(sel))
                break;
            return TCLOD_OK;
        }
    }
    if (rc == 0)
        return TCLOD_OK;
    clear_heaps(sel);
    return TCLOD_ERR_CALLBACK;
}

/* ---- buffers ------------------------------------------------------------------ */

size_t tclod_greedy_buffers(tclod_greedy_state *g, tclod_array *out) {
    size_t n = 0;
    /* increments are NaN until computed; no heap slot is TCLOD_NONE */
    out[n++] = (tclod_array){(void **)&g->delta, sizeof(tclod_delta), 0xff};
    out[n++] = (tclod_array){(void **)&g->inc_slot, sizeof(uint32_t), 0xff};
    out[n++] = (tclod_array){(void **)&g->cheap_slot, sizeof(uint32_t), 0xff};
    out[n++] = (tclod_array){(void **)&g->dec_slot, sizeof(uint32_t), 0xff};
    out[n++] = (tclod_array){(void **)&g->inc_block, sizeof(tclod_heap_entry), -1};
    out[n++] = (tclod_array){(void **)&g->cheap_block, sizeof(tclod_heap_entry), -1};
    out[n++] = (tclod_array){(void **)&g->dec_block, sizeof(tclod_heap_entry), -1};
    out[n++] = (tclod_array){(void **)&g->audit_cut, sizeof(tclod_id), -1};
    return n;
}

/* Where a heap's entries start in its block: entry 1 on a 64-byte boundary,
 * so that every slot's four children lie in one cache line. Up to three
 * entries are skipped. */
static tclod_heap_entry *heap_items(tclod_heap_entry *block) {
    uintptr_t a = (uintptr_t)(void *)block;
    if (a % sizeof(tclod_heap_entry) != 0)
        return block;
    return block + (64u + 48u - a % 64u) % 64u / sizeof(tclod_heap_entry);
}

/* The heaps find their entries in their blocks and their slots in dense
 * arrays. */
void tclod_greedy_bind(tclod_greedy_state *g) {
    g->inc.items = heap_items(g->inc_block);
    g->cheap.items = heap_items(g->cheap_block);
    g->dec.items = heap_items(g->dec_block);
    g->inc.pos = g->inc_slot;
    g->cheap.pos = g->cheap_slot;
    g->dec.pos = g->dec_slot;
}

/* ---- the steps the mixed solver interleaves with its smooth ones ------------ */

int tclod_greedy_start(tclod_selector *sel) {
    return tclod_greedy_start_cold(sel);
}

tclod_id tclod_greedy_candidate(tclod_selector *sel, double *ratio, int *skipped) {
    for (;;) {
        tclod_id n;
        if (sel->greedy.inc.count == 0)
            return TCLOD_NONE;
        n = sel->greedy.inc.items[0].id;
        if (greedy_increment_fits(sel, n)) {
            *ratio = sel->greedy.inc.items[0].key;
            return n;
        }
        *skipped = 1;
        if (!increment_may_fit(sel))
            return TCLOD_NONE;
        /* smooth steps only add cost too: a misfit never fits again */
        if (sel->resume.greedy.use_alt)
            greedy_consider_alternative(sel, n);
        skip_misfit(sel, n);
    }
}

double tclod_greedy_increment_cost(const tclod_selector *sel, tclod_id n) {
    return sel->greedy.delta[n].delta_c;
}

void tclod_greedy_skip(tclod_selector *sel) {
    tclod_id n = pop_increment(sel);
    sel->stats.iterations++;
    if (sel->resume.greedy.use_alt)
        greedy_consider_alternative(sel, n);
}

int tclod_greedy_take(tclod_selector *sel, tclod_id n) {
    sel->stats.iterations++;
    return apply_increment_cold(sel, n);
}

int tclod_greedy_enforce(tclod_selector *sel) {
    return enforce_budget(sel, 0);
}

void tclod_greedy_end(tclod_selector *sel) {
    clear_heaps(sel);
}
