#!/usr/bin/env bash
# best.sh OUT (session 30): from time-plans.sh's reports, each plan's locations and predicted time, and its process
# CPU time per vertex in each pass and the best of them, per mesh; then each plan over the mesh's fastest.
cd "$1" || exit 1
printf "%-5s %-22s %9s %10s  %-20s %8s %8s\n" mesh plan locations predicted "passes (ns/vertex)" best /fastest
for f in pass*-*.txt; do
  b=${f%.txt}; pass=${b%%-*}; rest=${b#*-}; mesh=${rest%%-*}; plan=${rest#*-}
  grep -E '^\| generated \| pass' "$f" | awk -F'|' -v m="$mesh" -v p="$plan" -v s="$pass" '{split($13, t, " "); print m, p, s, $5 + 0, $7 + 0, t[1]}'
done | sort -k1,1 -k2,2 -k3,3 | awk '
  { key = $1 " " $2; loc[key] = $4; pred[key] = $5; runs[key] = runs[key] sprintf(" %8.2f", $6);
    if (!(key in best) || $6 < best[key]) best[key] = $6; if (!($1 in fast) || $6 < fast[$1]) fast[$1] = $6 }
  END { for (k in best) { split(k, a, " "); printf "%-5s %-22s %9d %10.2f  %-20s %8.2f %8.3f\n", a[1], a[2], loc[k], pred[k], runs[k], best[k], best[k] / fast[a[1]] } }' | sort
