#!/usr/bin/env bash
# The touching hand as a contact (after the fact, spent stances): docs/studies/hand-contacts.md.
# Every stance: validate --controller id --rigid-impact with its set's scoring flags (the set's
# protocol), without and with --touch-contact, one after the other; each answer appended to
# studies/touch_contact/results.jsonl as it ends. From the repository root:
#   TOL=0.1 bash studies/touch_contact/run.sh studies/held_out_11/icub_*.yaml ...
set -u
out=studies/touch_contact/results.jsonl
TOL=${TOL:-0.1}
tmp=$(mktemp)
flags_for() {  # set 11 adds --friction-scale controller to the default
  case "$1" in
    *held_out_11/*) echo "--angular-momentum-damping-time controller --com-reach --friction-scale controller" ;;
    *) echo "--angular-momentum-damping-time controller --com-reach" ;;
  esac
}
for f in "$@"; do
  for touch in "" "--touch-contact"; do
    start=$(date +%s)
    # shellcheck disable=SC2046
    nice -n 5 impact-balance validate "$f" --controller id --rigid-impact $(flags_for "$f") \
      --tolerance "$TOL" --max-speed 4 --no-journal --json $touch > "$tmp" 2>/dev/null
    rc=$?
    python - "$f" "${touch:-none}" "$rc" "$(( $(date +%s) - start ))" "$(cut -d' ' -f1 /proc/loadavg)" "$tmp" "$TOL" >> "$out" <<'PY'
import json, sys
f, touch, rc, wall, load, path, tol = sys.argv[1:]
row = {"stance": f, "touch_contact": touch != "none", "rc": int(rc), "wall_s": int(wall),
       "load1": float(load), "tolerance": float(tol)}
try:
    d = json.load(open(path))
except Exception:
    d = None
if d:
    e, p = d["empirical"], d["predicted"]
    row.update(
        survived=e.get("survived"), fell=e.get("fell"), strict_failed=e.get("strict_failed"),
        strict_stood=e.get("strict_stood"), first_contact_break=e.get("first_contact_break"),
        predicted_default=p.get("default"),
        predicted_within_reach=(d.get("verdict") or {}).get("predicted"),
        trials=[[t["speed"], t["approach_speed_measured"], t["outcome"], t["strict_fail"],
                 t.get("strict_reason")] for t in d.get("trials", [])],
        gains_touch_contact=d["controller"]["gains"].get("touch_contact"),
    )
print(json.dumps(row))
PY
    tail -1 "$out" | cut -c1-300
  done
done
rm -f "$tmp"
