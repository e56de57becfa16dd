# The figures of docs/benchmarks.md, drawn from the benchmarks' CSV files with nothing
# but gnuplot (Debian: apt-get install gnuplot-nox; 5.4 or later for "with table if").
#
#   gnuplot bench/plots.gp                              # data in docs/figures/data
#   gnuplot -e "data='DIR'; out='DIR'" bench/plots.gp
#
# Reads, from `data`:
#   bench.csv                   tclod_bench (full run)
#   quality.csv                 tclod_quality (full run)
#   frame_time_greedy.csv       flyover_sim --simulate-gpu --csv, greedy solver
#   frame_time_robin_hood.csv   the same with --solver robin_hood
# and writes to `out`: selection_time.png, quality_chains.png, quality_trees.png,
# quality_world.png, frame_time_solvers.png. bench/figures.sh makes the data and runs this.

if (!exists("data")) data = "docs/figures/data"
if (!exists("out")) out = "docs/figures"

bench = data . "/bench.csv"
quality = data . "/quality.csv"

# noenhanced: method names have underscores, which enhanced text would turn into
# subscripts.
set terminal pngcairo size 1000,700 font "sans,11" noenhanced
set grid
set key outside right top
set datafile separator ","

# One colour per method, the same in every figure.
names = "greedy greedy_warm mixed robin_hood threshold_tuned threshold_fixed pq_stop flat " . \
        "greedy_lookahead greedy_restarts"
colours = "#1f77b4 #17becf #2ca02c #d62728 #9467bd #8c564b #ff7f0e #7f7f7f #bcbd22 #e377c2"
colour(m) = word(colours, index_of(m))
index_of(m) = sum [i = 1:words(names)] (word(names, i) eq m ? i : 0)

# filter(block, file, xcol, ycol, condition): rows of file where condition holds, columns
# xcol and ycol, into datablock block (gnuplot draws lines only through contiguous rows).
# The condition is gnuplot text evaluated per row, e.g. "strcol(1) eq 'random'".
filter = "set datafile separator ','; set table %s; " . \
         "plot '%s' using %d:%d with table if (%s); unset table"

# ---- selection time against scene size ---------------------------------------------
series = "greedy:cold greedy:warm mixed:cold robin_hood:cold threshold_tuned:cold " . \
         "threshold_fixed:cold pq_stop:cold flat:cold"
do for [i = 1:words(series)] {
    s = word(series, i)
    solver = s[1:strstrt(s, ":") - 1]
    mode = s[strstrt(s, ":") + 1:]
    eval sprintf(filter, sprintf("$time%d", i), bench, 4, 6, \
                 sprintf("strcol(1) eq 'random' && strcol(2) eq '%s' && strcol(3) eq '%s'", \
                         solver, mode))
}
set datafile separator whitespace
set output out . "/selection_time.png"
set title "Selection time per frame, random world (objects x 4 levels under group impostors)"
set xlabel "objects"
set ylabel "median time per frame (us)"
set logscale xy
set format x "%.0f"
set format y "%g"
cmd = "plot "
do for [i = 1:words(series)] {
    s = word(series, i)
    solver = s[1:strstrt(s, ":") - 1]
    mode = s[strstrt(s, ":") + 1:]
    key = mode eq "warm" ? solver . "_warm" : solver
    label = mode eq "warm" ? solver . " (warm)" : solver
    cmd = cmd . sprintf("$time%d using 1:2 with linespoints lw 2 pt 7 lc rgb '%s' " . \
                        "title '%s'%s", i, colour(key), label, i < words(series) ? ", " : "")
}
eval cmd
unset logscale
set format x "% h"
set format y "% h"

# ---- quality against budget: families ------------------------------------------------
families = "uncorrelated weak strong not_diminishing"
do for [shape in "chains trees"] {
    methods = shape eq "chains" ? \
        "greedy greedy_lookahead greedy_restarts mixed robin_hood pq_stop flat" : \
        "greedy greedy_lookahead greedy_restarts mixed robin_hood pq_stop"
    do for [f = 1:words(families)] {
        do for [m = 1:words(methods)] {
            cond = sprintf("strcol(1) eq 'families' && strcol(2) eq '%s' && " . \
                           "strcol(3) eq '%s' && strcol(4) eq '%s' && strcol(5) ne 'all'", \
                           shape, word(families, f), word(methods, m))
            eval sprintf(filter, sprintf("$median_%d_%d", f, m), quality, 5, 7, cond)
            eval sprintf(filter, sprintf("$worst_%d_%d", f, m), quality, 5, 8, cond)
        }
    }
    set datafile separator whitespace
    set output out . sprintf("/quality_%s.png", shape)
    set multiplot layout 2,2 title sprintf("Benefit / exact optimum, random %s: " . \
        "median (solid) and worst (dashed) of the instances", shape)
    set key inside right bottom font ",9"
    set xlabel "budget: roots + f x (finest - roots)"
    set ylabel "benefit / optimum"
    set xrange [0:1]
    set yrange [0.2:1.02]
    do for [f = 1:words(families)] {
        set title word(families, f)
        cmd = "plot "
        do for [m = 1:words(methods)] {
            meth = word(methods, m)
            cmd = cmd . sprintf("$median_%d_%d using 1:2 with linespoints lw 2 pt 7 ps 0.6 " . \
                                "lc rgb '%s' title '%s', $worst_%d_%d using 1:2 with lines " . \
                                "lw 1 dt 2 lc rgb '%s' notitle%s", f, m, colour(meth), meth, \
                                f, m, colour(meth), m < words(methods) ? ", " : "")
        }
        eval cmd
    }
    unset multiplot
    set datafile separator ","
}
set key outside right top font ",11"
unset xrange
unset yrange

# ---- quality against budget: the benchmark's scenes ----------------------------------
scenes = "random_1000 random_10000 flyover"
methods = "greedy mixed robin_hood threshold_tuned threshold_fixed pq_stop flat"
do for [sc = 1:words(scenes)] {
    do for [m = 1:words(methods)] {
        cond = sprintf("strcol(1) eq 'world' && strcol(2) eq '%s' && strcol(4) eq '%s' && " . \
                       "strcol(5) ne 'all'", word(scenes, sc), word(methods, m))
        eval sprintf(filter, sprintf("$world_%d_%d", sc, m), quality, 5, 7, cond)
    }
}
set datafile separator whitespace
set terminal pngcairo size 1500,650 font "sans,11" noenhanced
set output out . "/quality_world.png"
set multiplot layout 1,3 title "Benefit / upper bound (Lagrangian), median over views along " . \
    "the camera loop (mixed draws over greedy: the same selections)"
set key inside right bottom font ",9"
set logscale x 2
set xlabel "budget / the benchmark's budget"
set ylabel "benefit / upper bound (a lower bound on benefit / optimum)"
set yrange [0:1.02]
do for [sc = 1:words(scenes)] {
    set title word(scenes, sc)
    cmd = "plot "
    do for [m = 1:words(methods)] {
        meth = word(methods, m)
        # the flyover has no flat rows
        if (!(word(scenes, sc) eq "flyover" && meth eq "flat")) {
            cmd = cmd . sprintf("$world_%d_%d using 1:2 with linespoints lw 2 pt 7 ps 0.6 " . \
                                "lc rgb '%s' title '%s', ", sc, m, colour(meth), meth)
        }
    }
    eval cmd[1:strlen(cmd) - 2]
}
unset multiplot
unset logscale
unset yrange
set terminal pngcairo size 1000,700 font "sans,11" noenhanced

# ---- frame time against the target along the camera path --------------------------------
set datafile separator ","
set output out . "/frame_time_solvers.png"
set title "Flyover with a simulated GPU (flyover_sim --simulate-gpu): frame time per frame"
set xlabel "frame (one loop of the camera path = 2400 frames)"
set ylabel "frame time (ms, log scale)"
set key outside right top font ",11"
# The frame without LOD is tens of times the target: a log scale shows both.
set logscale y
set yrange [*:*]
plot data . "/frame_time_greedy.csv" using 1:13 every ::1 with lines lw 1 \
         lc rgb colour("greedy") title "greedy (warm)", \
     data . "/frame_time_robin_hood.csv" using 1:13 every ::1 with lines lw 1 \
         lc rgb colour("robin_hood") title "robin_hood", \
     data . "/frame_time_greedy.csv" using 1:14 every ::1 with lines lw 2 dt 2 \
         lc rgb "black" title "target", \
     data . "/frame_time_greedy.csv" using 1:16 every ::1 with lines lw 1 dt 3 \
         lc rgb "#999999" title "without LOD (all finest)"
unset logscale y
unset output
