# gnuplot plot.gp: kdamond_stalls.png from the two .dat files (docs/performance.md, "Real time at 128 processes")
set terminal pngcairo size 1000,400 font "sans,10"
set output "kdamond_stalls.png"
set title "128 agent processes in real time, 2026-11-27: the kernel's memory monitor and the late ticks"
set xlabel "time (s)"
set ylabel "kdamond.0, share of one core (20 ms bins)"
set yrange [0:1.2]
set xrange [0:4.2]
set key below
plot "kdamond_cpu.dat" using 1:2 with steps lw 2 lc rgb "#1f77b4" title "kdamond.0 CPU", \
     "late_ticks.dat" using 1:(1.1) with points pt 7 ps 0.8 lc rgb "#d62728" title "tick with > 32 of 128 answers later than 20 ms"
