#!/usr/bin/env bash
# How the closed loop's cost grows (issue 15's scaling table): run time,
# real-time factor, peak memory and the stages' wall milliseconds per
# simulated second, against the laps driven (one and ten, on FSG 2023 and on
# a 1 km track), the cone count (up to 2,000), the LiDAR's resolution
# (32x1024, 64x1024, 128x2048) and FastSLAM's particles. Each row is one
# `paddock run` of its own, one after another (a process each: its peak
# memory is its own; nothing else should run meanwhile).
#   tools/scaling_table.sh [--set section.key=value]...   (added to every run)
# Prints a Markdown table. Runs ./paddock (which builds first).
#
# The 1 km track is generated here: an ellipse of semi-axes 200 m and 110 m
# (994.6 m round, its tightest radius 60.5 m), blue cones 1.5 m to the left
# of it and yellow ones 1.5 m to the right: 200 a side (5 m apart) or
# 1,000 a side (1 m apart).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
out="$(mktemp -d)"
trap 'rm -rf "$out"' EXIT

# ellipse CONES > FILE: the track CSV (tracks/README.md's format), CONES
# cones a side, evenly spaced along it
ellipse() {
  awk -v count="$1" 'BEGIN {
    a = 200; b = 110; half = 1.5; n = 200000; pi = atan2(0, -1)
    # the length round, by a fine polyline; then cones where it passes each
    # multiple of length / count
    len = 0; px = a; py = 0
    for (i = 1; i <= n; i++) {
      t = 2 * pi * i / n; x = a * cos(t); y = b * sin(t)
      len += sqrt((x - px) ^ 2 + (y - py) ^ 2); px = x; py = y
    }
    spacing = len / count
    # the car 3 m before the timekeeping line across (200, 0), heading up (+y)
    print "# start 200.0000 -3.0000 1.570796"
    printf "# description: an ellipse 200 m x 110 m (semi-axes, %.1f m round), %d cones a side %.3f m apart (tools/scaling_table.sh); longer than the rules lap of 200 to 500 m on purpose\n", len, count, spacing
    print "# timekeeping 196.0000 0.0000"
    print "# timekeeping 204.0000 0.0000"
    print "tag,x,y"
    s = 0; next_at = 0; px = a; py = 0
    for (i = 0; i <= n; i++) {
      t = 2 * pi * i / n
      x = a * cos(t); y = b * sin(t)
      if (i > 0) s += sqrt((x - px) ^ 2 + (y - py) ^ 2)
      px = x; py = y
      if (s + 1e-9 >= next_at && i < n && placed < count) {
        # the unit normal pointing out of the ellipse, (b cos t, a sin t) / |.|
        nx = b * cos(t); ny = a * sin(t); l = sqrt(nx * nx + ny * ny); nx /= l; ny /= l
        # counter-clockwise: the outside is on the right (yellow), the inside on the left (blue)
        printf "blue,%.4f,%.4f\n", x - half * nx, y - half * ny
        printf "yellow,%.4f,%.4f\n", x + half * nx, y + half * ny
        next_at += spacing; placed++
      }
    }
  }'
}
ellipse 200 > "$out/ellipse_5m.csv"
ellipse 1000 > "$out/ellipse_1m.csv"

# the scenarios on the generated track: the shipped ones with its track
for event in autocross trackdrive; do
  for sp in 5m 1m; do
    cat > "$out/ellipse_${sp}_${event}.ini" <<EOF
include = $root/scenarios/fsg_2023_${event}.ini
[scenario]
track = ellipse_${sp}.csv
EOF
  done
done

fsg="$root/scenarios/fsg_2023"
runs=(
  "FSG 2023 autocross: 1 lap (194 cones)|$fsg""_autocross.ini|"
  "FSG 2023 trackdrive: 10 laps (194 cones)|$fsg""_trackdrive.ini|"
  "1 km ellipse autocross: 1 lap, 400 cones|$out/ellipse_5m_autocross.ini|"
  "1 km ellipse trackdrive: 10 laps, 400 cones|$out/ellipse_5m_trackdrive.ini|"
  "1 km ellipse autocross: 1 lap, 2,000 cones|$out/ellipse_1m_autocross.ini|"
  "FSG 2023 autocross, LiDAR 64 x 1024|$fsg""_autocross.ini|--set lidar.channels=64"
  "FSG 2023 autocross, LiDAR 128 x 2048|$fsg""_autocross.ini|--set lidar.channels=128 --set lidar.columns=2048"
  "FSG 2023 autocross, 50 particles|$fsg""_autocross.ini|--set slam.particles=50"
  "FSG 2023 autocross, 100 particles|$fsg""_autocross.ini|--set slam.particles=100"
  "FSG 2023 autocross, 400 particles|$fsg""_autocross.ini|--set slam.particles=400"
)

"$root/paddock" keys >/dev/null  # builds
stages=(localisation perception camera lidar planning physics)
printf '| run | simulated s | wall s | x real time | peak MiB | finished |'
for st in "${stages[@]}"; do printf ' %s |' "$st"; done
printf ' rest |\n|---|---:|---:|---:|---:|---|'
for _ in "${stages[@]}"; do printf -- '---:|'; done
printf -- '---:|\n'
for i in "${!runs[@]}"; do
  IFS='|' read -r name scenario sets <<<"${runs[$i]}"
  # shellcheck disable=SC2086
  if ! "$root/build/paddock" run "$scenario" $sets "$@" --quiet --out "$out/run$i" >/dev/null 2>"$out/err$i"; then
    [ -f "$out/run$i/summary.json" ] || { echo "| $name | run failed: $(head -c 200 "$out/err$i" | tr '\n|' '  ') |"; continue; }
  fi
  # the figures from summary.json (one number of a flat key; the profile's
  # stages are the first keys of those names after "profile")
  s="$out/run$i/summary.json"
  num() { grep -o "\"$1\":[^,}]*" "$s" | head -1 | cut -d: -f2; }
  prof="$(grep -o '"profile":{[^}]*}' "$s")"
  stage() { grep -o "\"$1\":[^,}]*" <<<"$prof" | head -1 | cut -d: -f2; }
  sim="$(num sim_time)"
  wall="$(num wall_time)"
  total=0
  row=""
  for st in "${stages[@]}"; do
    v="$(stage "$st")"
    row="$row $(awk -v v="$v" -v t="$sim" 'BEGIN { printf "%.1f", 1000 * v / t }') |"
    total="$(awk -v a="$total" -v v="$v" 'BEGIN { print a + v }')"
  done
  loop="$(awk -v p="$prof" 'BEGIN { n = split(p, kv, ","); s = 0; for (k = 1; k <= n; k++) { split(kv[k], x, ":"); s += x[2] } print s }')"
  rest="$(awk -v l="$loop" -v a="$total" -v t="$sim" 'BEGIN { printf "%.1f", 1000 * (l - a) / t }')"
  printf '| %s | %.1f | %.2f | %.1f | %.0f | %s |%s %s |\n' "$name" "$sim" "$wall" \
    "$(awk -v s="$sim" -v w="$wall" 'BEGIN { print s / w }')" "$(num peak_rss_mb)" "$(num finished)" "$row" "$rest"
done
