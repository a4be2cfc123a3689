#!/usr/bin/env bash
# Regenerates the synthetic example data of docs/fitting.md (run from the repository root after building).
set -euo pipefail
B=./build/release/oobleck
mkdir -p out/fit
# 1. flow curves of the dhaene1993 set at 11 volume fractions (our "rheometer")
$B rheology flow-curve --preset dhaene1993 --points 50 --out out/fit/flow_curves.csv \
  $(for p in 0.30 0.40 0.45 0.50 0.52 0.54 0.55 0.56 0.58 0.60 0.62; do echo --phi $p; done)
# 2. minimum / plateau viscosity per phi (column 7 = viscosity [Pa s]; data rows only, not the
#    "# units:" and header lines), with +-2 % scatter
awk -F, 'BEGIN{srand(7)} /^[0-9]/{if(!($1 in m)||$7<m[$1])m[$1]=$7}
  END{print "phi,viscosity"; for(p in m) printf "%.3f,%.5g\n",p,m[p]*(1+0.04*(rand()-0.5))}' \
  out/fit/flow_curves.csv | sort -n > docs/fitting/min_viscosity.csv
awk -F, 'BEGIN{srand(8)} /^[0-9]/ && $1<0.565 {if(!($1 in m)||$7>m[$1])m[$1]=$7}
  END{print "phi,viscosity"; for(p in m) printf "%.3f,%.5g\n",p,m[p]*(1+0.04*(rand()-0.5))}' \
  out/fit/flow_curves.csv | sort -n > docs/fitting/plateau_viscosity.csv
# 3. DST onset rates (E14) between phi_c and phi_j, with +-2 % scatter
(echo phi,shear_rate_dst
 for p in 0.572 0.58 0.59 0.60 0.61 0.62 0.63 0.635 0.64 0.645; do
   echo "$p,$($B rheology dst --preset dhaene1993 --phi $p --json | sed 's/.*"shear_rate_dst":\([^,}]*\).*/\1/')"
 done) | awk -F, 'BEGIN{srand(9)} NR==1{print;next}{printf "%s,%.4g\n",$1,$2*(1+0.04*(rand()-0.5))}' \
  > docs/fitting/dst_rates.csv
for f in min_viscosity plateau_viscosity dst_rates; do
  sed -i '1i # synthetic example: dhaene1993 (PMMA) from oobleck itself with +-2 % scatter; see docs/fitting.md' \
    docs/fitting/$f.csv
done
