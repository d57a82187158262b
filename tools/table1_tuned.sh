#!/usr/bin/env bash
# The paper's Table I answered (issue 12): does a tuning exist where the
# combined lateral controller laps faster than Stanley and pure pursuit
# alone? Each controller is tuned with the same budget
# (scenarios/tunes/table1_<controller>.ini: 40 evaluations of Subplex over its
# own gains, the objective the mean cost over FSG 2023, FS Spain 2019 and FS
# East 2023 trackdrives planned from the cone sensor with the true state),
# then each controller runs every track with the shipped gains and with its
# tuned ones. Prints a Markdown table.
#   tools/table1_tuned.sh [--no-tune]   (--no-tune: use runs/table1_*/best.ini as they are)
# Runs ./paddock (which builds first).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
controllers=(combined stanley pure_pursuit)
tracks=(fsg_2023_trackdrive fss_2019_trackdrive fse_2023_trackdrive)
tune=1
[ "${1:-}" = "--no-tune" ] && tune=0
out="$(mktemp -d)"
trap 'rm -rf "$out"' EXIT

"$root/paddock" keys >/dev/null
bin="$root/build/paddock"
for c in "${controllers[@]}"; do
  if [ "$tune" = 1 ] || [ ! -f "$root/runs/table1_$c/best.ini" ]; then
    "$bin" tune "$root/scenarios/tunes/table1_$c.ini" --out "$root/runs/table1_$c" >&2
  fi
done

# best.ini's [section] key = value lines as --set arguments
sets_of() {
  awk '/^\[/ { s = substr($0, 2, index($0, "]") - 2); next }
       /^[a-zA-Z_]/ && s != "" { print "--set " s "." $1 "=" $3 }' "$1"
}

# the paper's stack (the shipped scenarios race)
paper="$(sets_of "$root/scenarios/paper.ini")"

# every run side by side (as many as cores)
jobs="$(nproc)"
for c in "${controllers[@]}"; do
  for t in "${tracks[@]}"; do
    for tuning in shipped tuned; do
      while [ "$(jobs -rp | wc -l)" -ge "$jobs" ]; do sleep 0.2; done
      extra=""
      [ "$tuning" = tuned ] && extra="$(sets_of "$root/runs/table1_$c/best.ini")"
      # shellcheck disable=SC2086
      "$bin" run "$root/scenarios/$t.ini" $paper --set autonomy.perception=ground_truth --set autonomy.slam=ground_truth \
        --set control.lateral="$c" $extra --quiet --out "$out/$c.$t.$tuning" >/dev/null 2>"$out/$c.$t.$tuning.err" &
    done
  done
done
wait

field() { grep -o "\"$2\":[^,}]*" "$1" | head -1 | cut -d: -f2; }
echo "| controller | gains | $(printf '%s total [s] (DOO) | ' "${tracks[@]}")sum [s] | mean tracking RMS [m] |"
echo "|---|---|$(printf -- '---|%.0s' "${tracks[@]}")---|---|"
for c in "${controllers[@]}"; do
  for tuning in shipped tuned; do
    row="| $c | $tuning |"
    sum=0
    rms=0
    for t in "${tracks[@]}"; do
      s="$out/$c.$t.$tuning/summary.json"
      if [ "$(field "$s" finished)" != true ]; then
        row="$row DNF |"
        sum=nan
        continue
      fi
      total="$(field "$s" total_time)"
      doo="$(grep -o '"penalties":{"doo":[0-9]*' "$s" | grep -o '[0-9]*$')"
      r="$(grep -o '"tracking":{"rms":[^,]*' "$s" | tail -1 | cut -d: -f3)"
      row="$row $(printf '%.3f' "$total") ($doo) |"
      sum="$(awk -v a="$sum" -v b="$total" 'BEGIN { print (a == "nan") ? "nan" : a + b }')"
      rms="$(awk -v a="$rms" -v b="$r" 'BEGIN { print a + b }')"
    done
    echo "$row $( [ "$sum" = nan ] && echo DNF || printf '%.3f' "$sum") | $(awk -v a="$rms" -v n="${#tracks[@]}" 'BEGIN { printf "%.3f", a / n }') |"
  done
done
echo
for c in "${controllers[@]}"; do
  echo "$c tuned: $(grep -v '^;' "$root/runs/table1_$c/best.ini" | grep -v '^$' | tr '\n' ' ')"
done
