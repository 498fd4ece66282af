set terminal pngcairo size 900,560 font 'sans,10'
set output 'fig10_trends.png'
set datafile separator ','
set key autotitle columnhead
set grid
set multiplot layout 1,2
set xlabel 'damage (%)'
set ylabel 'STD of inferred GVW (t)'
plot 'table4_batches.csv' u ($3*100):(strcol(1) eq 'ideal' ? $8 : 1/0) w p pt 7 t 'ideal', '' u ($3*100):(strcol(1) eq 'table5' ? $8 : 1/0) w p pt 5 t 'Table 5 inaccuracies', '' u ($3*100+0.3):(strcol(1) eq 'table5_same' ? $8 : 1/0) w p pt 9 t 'Table 5, same vehicles'
set ylabel 'mean of inferred GVW (t)'
plot 'table4_batches.csv' u ($3*100):(strcol(1) eq 'ideal' ? $7 : 1/0) w p pt 7 t 'ideal', '' u ($3*100):(strcol(1) eq 'table5' ? $7 : 1/0) w p pt 5 t 'Table 5 inaccuracies', '' u ($3*100+0.3):(strcol(1) eq 'table5_same' ? $7 : 1/0) w p pt 9 t 'Table 5, same vehicles'
unset multiplot
