#!/usr/bin/env bash
# Behaviour references of issue 18: every machine config under config/machines/ and
# config/bench/controllers/, run on the virtual clock with a fixed seed, must give a byte-identical
# trace before and after a refactor. Only the SHA-256 of each trace is committed
# (tests/reference/traces.sha256); the CSVs are ~0.8 MB each.
#
#   tests/reference/record.sh                 record: run every config twice (determinism), write
#                                             traces.sha256 (and vars/*.vars, see below), and
#                                             jobs.fnv64 through edm_programs_tests (the job
#                                             references: drill-sim/drill-fuzzy-sim running
#                                             examples/parts/drill-then-finish.nc)
#   tests/reference/record.sh --check         compare with traces.sha256 (ctest reference.traces)
#   options: --edmplc PATH (default build/bin/edmplc), --keep DIR (keep the CSVs there, to diff
#            them against a recording made at an older commit)
#
# A config without a `trace:` section (three bench controllers, driven by the bench driver) is
# traced through a temporary copy with a `trace:` section added: its own outputs and the plant's
# (io.*), at most program.block.pin deep, 32 at most. That list is fixed at recording time in
# tests/reference/vars/NAME.vars so that a refactor which adds variables does not change the trace
# (delete the file to choose the list again when recording).
#
# Re-record ONLY when a change of behaviour is intended, and say in the commit which trace changed
# and why. Never re-record to make a refactor pass.
set -u
# The shipped configs retain into the state directory; the references run without one, so no
# retain file of an earlier run (a worn electrode, an interrupted job) changes a trace.
unset EDM_STATE_DIR

root=$(cd "$(dirname "$0")/../.." && pwd)
ref_dir="$root/tests/reference"
sums="$ref_dir/traces.sha256"
edmplc="$root/build/bin/edmplc"
mode=record
keep=""
run_for=10s
seed=1

while [ $# -gt 0 ]; do
  case "$1" in
    --check) mode=check ;;
    --edmplc) edmplc="$2"; shift ;;
    --keep) keep="$2"; shift ;;
    *) echo "usage: $0 [--check] [--edmplc PATH] [--keep DIR]" >&2; exit 2 ;;
  esac
  shift
done

if [ ! -x "$edmplc" ]; then
  echo "reference: no edmplc at $edmplc (build it: edm-b --target edmplc)" >&2
  exit 2
fi
tmp=$(mktemp -d "${TMPDIR:-/tmp}/edm-reference.XXXXXX") || exit 2
trap 'rm -rf "$tmp"' EXIT
[ -n "$keep" ] && mkdir -p "$keep"

# Prints the SHA-256 of the trace of config $1 (path relative to the repo), or fails.
trace_hash() {
  local rel="$1" cfg="$root/$1" name vars
  name=$(basename "$rel" .yaml)
  if ! grep -q '^trace:' "$cfg"; then
    vars="$ref_dir/vars/$name.vars"
    if [ "$mode" = record ] && [ ! -f "$vars" ]; then
      mkdir -p "$ref_dir/vars"
      # The plant's outputs first (less its histograms, counters and wire/kerf state), then the
      # blocks' own; a task traces at most 32 variables.
      "$edmplc" --config "$cfg" --list-vars |
        awk -F'\t' '$2 == "output" && split($1, p, ".") <= 3 { print $1 }' |
        grep -Ev '^io\.(hist_|n_|wire_|true_kerf|wall_radius)' |
        awk '/^io\./ { print; next } { rest = rest $0 "\n" } END { printf "%s", rest }' |
        head -n 32 > "$vars" || return 1
    fi
    if [ ! -s "$vars" ]; then
      echo "reference: $rel has no trace section and no $vars" >&2
      return 1
    fi
    # The copy stands beside nothing: these configs name no other file.
    { cat "$cfg"; printf '\ntrace:\n  variables: [%s]\n' "$(paste -sd, "$vars")"; } \
      > "$tmp/$name.yaml"
    cfg="$tmp/$name.yaml"
  fi
  local csv="$tmp/${rel//\//_}.csv"
  rm -f "$csv"
  if ! "$edmplc" --config "$cfg" --clock virtual --run-for "$run_for" --seed "$seed" \
      --bridge-port 0 --log-level warn --trace-out "$csv" > "$tmp/out.txt" 2>&1 ||
      [ ! -s "$csv" ]; then
    echo "reference: $rel: edmplc failed or wrote no trace:" >&2
    cat "$tmp/out.txt" >&2
    return 1
  fi
  [ -n "$keep" ] && cp "$csv" "$keep/"
  sha256sum < "$csv" | cut -d' ' -f1
}

# A config that needs outside equipment (a Modbus remote I/O: drill-modbus-sim.yaml, tested in
# tests/modbus/) says `edm-reference: skip` in a comment and has no reference.
configs=$(cd "$root" && grep -L 'edm-reference: skip' config/machines/*.yaml \
  config/bench/controllers/*.yaml)
status=0
if [ "$mode" = record ]; then
  : > "$tmp/sums"
  for rel in $configs; do
    h1=$(trace_hash "$rel") || exit 1
    h2=$(trace_hash "$rel") || exit 1
    if [ "$h1" != "$h2" ]; then
      echo "reference: $rel is not deterministic ($h1 then $h2); nothing recorded" >&2
      exit 1
    fi
    printf '%s  %s\n' "$h1" "$rel" >> "$tmp/sums"
    echo "recorded $rel"
  done
  cp "$tmp/sums" "$sums"
  echo "wrote $sums ($(wc -l < "$sums") configs, --run-for $run_for --seed $seed)"
  # The job references (tests/programs/job_reference_test.cpp: EdmJob running a part program,
  # which edmplc alone never does) are recorded by their own test.
  programs_tests="$(dirname "$edmplc")/edm_programs_tests"
  if [ -x "$programs_tests" ]; then
    EDM_RECORD_REFERENCES=1 "$programs_tests" --gtest_filter='Shipped/JobReference.*' \
      > "$tmp/out.txt" 2>&1 || { cat "$tmp/out.txt" >&2; exit 1; }
    echo "wrote $ref_dir/jobs.fnv64 (edm_programs_tests)"
  else
    echo "reference: no $programs_tests: tests/reference/jobs.fnv64 not re-recorded" >&2
    exit 1
  fi
  exit 0
fi

# --check: every config must be listed, and every listed config must still give its trace.
for rel in $configs; do
  grep -q "  $rel\$" "$sums" || {
    echo "reference: $rel has no reference in tests/reference/traces.sha256 (record it:" \
      "tests/reference/record.sh)" >&2
    status=1
  }
done
while read -r want rel; do
  [ -f "$root/$rel" ] || { echo "reference: $rel is gone (re-record)" >&2; status=1; continue; }
  got=$(trace_hash "$rel") || { status=1; continue; }
  if [ "$got" = "$want" ]; then
    echo "same     $rel"
  else
    echo "CHANGED  $rel: its trace (--clock virtual --run-for $run_for --seed $seed) differs" \
      "from the reference (sha256 $want, now $got)." >&2
    echo "         If the change of behaviour is intended, re-record with" \
      "tests/reference/record.sh and say in the commit which trace changed and why;" \
      "to see how, run record.sh --keep DIR here and at the previous commit and diff." >&2
    status=1
  fi
done < "$sums"
exit $status
