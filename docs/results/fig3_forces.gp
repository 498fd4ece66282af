set terminal pngcairo size 900,560 font 'sans,10'
set output 'fig3_forces.png'
set datafile separator ','
set key autotitle columnhead
set grid
set xlabel 'position of axle 1 (m)'
set ylabel 'axle force (kN)'
set xrange [-2:27]
plot 'fig3_forces.csv' u 1:2 w l lw 2 t 'true axle 1', '' u 1:3 w l lw 2 t 'true axle 2', '' u 1:4 w l t 'A-MFI axle 1 (L-curve)', '' u 1:5 w l t 'A-MFI axle 2 (L-curve)'
