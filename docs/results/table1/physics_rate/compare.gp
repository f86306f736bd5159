if (strstrt(GPVAL_TERMINALS, ' pngcairo ') > 0) {
  set terminal pngcairo size 900,500 noenhanced font 'sans,10'
} else {
  set terminal png size 900,500 noenhanced
}
set output 'compare.png'
data = 'compare.dat'
set title 'Task time per set, mean and standard deviation of the successful runs'
set ylabel 'Time to complete [s]'
set grid ytics
set offsets 0, 0, 2, 2
set key outside top center horizontal
set xrange [-0.6:3.6]
set xtics ('Sim 1' 0, 'Sim 2' 1, 'Sim 3' 2, 'Sim 4' 3)
plot data index 0 using 1:2:3 with yerrorbars pt 7 ps 1.2 lw 2 lc 1 title '1 kHz', \
     data index 1 using 1:2:3 with yerrorbars pt 7 ps 1.2 lw 2 lc 2 title '500 Hz', \
     data index 2 using 1:2:3 with yerrorbars pt 7 ps 1.2 lw 2 lc 3 title '250 Hz'
set terminal svg size 900,500 noenhanced
set output 'compare.svg'
replot
unset output
