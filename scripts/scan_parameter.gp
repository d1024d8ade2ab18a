# The figure of scripts/scan_parameter.py's files:
#   gnuplot -e "prefix='scan_mu_c'; name='mu_c'; out='scan.png'" scripts/scan_parameter.gp
set terminal pngcairo size 1200,460 font "DejaVu Sans,11" noenhanced
set output out
set multiplot layout 1,2 title sprintf("%s scanned over its value (scripts/scan_parameter.py)", name)
set title "the angle a least-squares cubic fits worst"
set xlabel sprintf("%s offset [%%]", name)
set ylabel "angle [deg]"
set key bottom center
set grid
plot prefix."_worst.dat" u 1:2 w lp pt 7 ps 0.6 lw 2 t "simulated", "" u 1:3 w l lw 1 dt 2 t "least-squares cubic"
set title "where the angles leave the cubics"
set xlabel "t [s]"
set ylabel "RMS residual to the cubics [deg]"
set y2label "RMS theta_x over the joints, middle run [deg]"
set y2tics
set ytics nomirror
set key top right
plot prefix."_frames.dat" u 1:2 w l lw 2 t "residual (left axis)", "" u 1:3 axes x1y2 w l lw 1 lc rgb "gray50" t "motion (right axis)"
unset multiplot
