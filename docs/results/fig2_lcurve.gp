set terminal pngcairo size 900,560 font 'sans,10'
set output 'fig2_lcurve.png'
set datafile separator ','
set key autotitle columnhead
set grid
set multiplot layout 1,2
set logscale xy
set xlabel 'residual norm (m/s^2)'
set ylabel 'smoothing norm (N)'
plot 'fig2_lcurve.csv' u 2:3 w lp t 'L-curve'
unset logscale y
set logscale x
set xlabel 'lambda_ref' noenhanced
set ylabel 'curvature'
plot 'fig2_lcurve.csv' u 1:4 w lp t 'curvature'
unset multiplot
