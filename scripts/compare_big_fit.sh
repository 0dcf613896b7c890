#!/usr/bin/env bash
# CPU time (user + system) and wall time of two builds of `fit` on 100 000 rows of distinct
# speeds, or of DATA (written by scripts/big_fit_data.py, as for scripts/time_big_fit.sh), run
# alternately so that both see the same load; prints the median and the least of each and the
# ratios of the medians. Quoted in the README (known limitations).
#
# Usage: bash scripts/compare_big_fit.sh OLD_BINARY NEW_BINARY [MODEL] [ROUNDS] [DATA]
#        (MODEL: vm, pm, min, product, powerlaw or all, default product; ROUNDS default 6;
#        DATA: distinct, repeated or sizes, default distinct)
set -euo pipefail
cd "$(dirname "$0")/.."
old=$1
new=$2
model=${3:-product}
rounds=${4:-6}
data=${5:-distinct}
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
python3 scripts/big_fit_data.py "$dir"
for i in $(seq "$rounds"); do
    for b in old new; do
        bin=$old
        [ "$b" = new ] && bin=$new
        /usr/bin/time -f "%U %S %e" -o "$dir/t" "$bin" fit "$dir/$data.csv" --material nylon \
            --model "$model" > /dev/null 2>&1 || true
        awk '{print $1 + $2}' "$dir/t" >> "$dir/$b"
        awk '{print $3}' "$dir/t" >> "$dir/$b.wall"
    done
done
median() { sort -n "$1" | awk '{a[NR] = $1} END {print a[int((NR + 1) / 2)]}'; }
least() { sort -n "$1" | head -1; }
mo=$(median "$dir/old")
mn=$(median "$dir/new")
lo=$(least "$dir/old")
ln=$(least "$dir/new")
ratio=$(awk -v a="$mn" -v b="$mo" 'BEGIN {printf "%.2f", a / b}')
echo "$model on $data.csv, $rounds alternate runs, CPU s (user + system): old median $mo (least $lo)," \
    "new median $mn (least $ln), ratio $ratio"
wo=$(median "$dir/old.wall")
wn=$(median "$dir/new.wall")
wratio=$(awk -v a="$wn" -v b="$wo" 'BEGIN {printf "%.2f", a / b}')
echo "$model, wall s: old median $wo (least $(least "$dir/old.wall")), new median $wn" \
    "(least $(least "$dir/new.wall")), ratio $wratio"
