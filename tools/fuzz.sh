#!/usr/bin/env bash
# Builds the libFuzzer targets (tests/fuzz, clang-14 with address, undefined and
# float-cast-overflow sanitizers) in build-fuzz, writes their seed corpora and runs them.
#
#   tools/fuzz.sh --smoke              every target for SPLAT_FUZZ_SMOKE_SECONDS (5) each:
#                                      the test command's check (tools/test.sh)
#   tools/fuzz.sh [SECONDS] [TARGET..] long runs (default 600 s each), at most
#                                      SPLAT_FUZZ_JOBS (2) at a time, under nice -n 19
#
# Corpora grow in build-fuzz/corpus/TARGET, findings land in build-fuzz/findings/TARGET,
# logs in build-fuzz/logs/TARGET.log; the last lines of each log (executions, cov, ft) are
# printed. Exit status: non-zero when a target found something or could not run. Without
# clang-14 the script fails (exit 1) when CI is set and is skipped (exit 0, message) otherwise.
set -euo pipefail
cd "$(dirname "$0")/.."

targets_all=(nifti nifti_gz nrrd metaimage raw dicom transfer zarr vdb)
smoke=0
seconds=600
if [[ "${1:-}" == "--smoke" ]]; then
  smoke=1
  seconds="${SPLAT_FUZZ_SMOKE_SECONDS:-5}"
  shift
elif [[ "${1:-}" =~ ^[0-9]+$ ]]; then
  seconds="$1"
  shift
fi
targets=("$@")
explicit=${#targets[@]}
[[ ${#targets[@]} -eq 0 ]] && targets=("${targets_all[@]}")
jobs="${SPLAT_FUZZ_JOBS:-2}"

if ! command -v clang++-14 >/dev/null || ! command -v clang-14 >/dev/null; then
  if [[ -n "${CI:-}" ]]; then
    echo "fuzz.sh: clang-14 is missing (apt-get install clang-14 libclang-rt-14-dev)" >&2
    exit 1
  fi
  echo "fuzz.sh: skipped: clang-14 is not installed (CI would fail here)" >&2
  exit 0
fi

build=build-fuzz
launcher=()
command -v ccache >/dev/null && launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
if [[ ! -f "$build/CMakeCache.txt" ]]; then
  CC=clang-14 CXX=clang++-14 cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    -DSPLAT_FUZZ=ON -DSPLAT_BUILD_TESTS=OFF "${launcher[@]}" >/dev/null
fi
if ! nice -n 19 cmake --build "$build" -j"${SPLAT_FUZZ_BUILD_JOBS:-2}" --target fuzz_all \
  >"$build/build.log" 2>&1; then
  tail -30 "$build/build.log" >&2
  echo "fuzz.sh: building the fuzz targets failed ($build/build.log)" >&2
  exit 1
fi

seeds="$build/seeds"
rm -rf "$seeds"
"$build/tests/fuzz/splat_fuzz_seeds" "$seeds" >/dev/null
# Third-party files as seeds (Debian's python3-nibabel and python3-pydicom test data, when
# installed): every DICOM for fuzz_dicom, every NIfTI-1/2 and ANALYZE pair for fuzz_nifti
# (a pair as header + kDataMarker + image, fuzz_util.h), every .nii.gz for fuzz_nifti_gz.
nib=/usr/lib/python3/dist-packages/nibabel
pyd=/usr/lib/python3/dist-packages/pydicom/data/test_files
third=0
for f in "$nib"/tests/data/*.dcm "$nib"/nicom/tests/data/*.dcm "$pyd"/*.dcm "$pyd"/*/*.dcm; do
  [[ -f $f ]] && cp "$f" "$seeds/dicom/third_$(basename "$f")" && third=$((third + 1))
done
for f in "$nib"/nicom/tests/data/*.dcm.gz; do
  [[ -f $f ]] && gzip -dc "$f" >"$seeds/dicom/third_$(basename "$f" .gz)" && third=$((third + 1))
done
for f in "$nib"/tests/data/*.nii; do
  [[ -f $f ]] && cp "$f" "$seeds/nifti/third_$(basename "$f")" && third=$((third + 1))
done
for f in "$nib"/tests/data/*.hdr; do
  img="${f%.hdr}.img"
  [[ -f $img ]] || continue
  { cat "$f"; printf '\n@@DATA@@\n'; cat "$img"; } >"$seeds/nifti/third_$(basename "$f")"
  third=$((third + 1))
done
for f in "$nib"/tests/data/*.nii.gz; do
  [[ -f $f ]] && gzip -dc "$f" >"$seeds/nifti_gz/third_$(basename "$f" .gz)" && third=$((third + 1))
done
[[ $third -gt 0 ]] && echo "fuzz.sh: $third third-party seed files (nibabel, pydicom)"
# Zarr and OpenVDB seeds written by the formats' own Python libraries (the readers' test
# data): each Zarr array as its .zarray, the data marker and its chunk 0.0.0 (fuzz_zarr.cpp).
mkdir -p "$seeds/zarr" "$seeds/vdb"
if /usr/bin/python3 tests/sparse/make_sparse_data.py "$build/sparse_data" >/dev/null 2>&1; then
  for a in "$build"/sparse_data/dtypes/*.zarr; do
    [[ -f $a/0.0.0 ]] || continue
    { cat "$a/.zarray"; printf '\n@@DATA@@\n'; cat "$a/0.0.0"; } >"$seeds/zarr/$(basename "$a")"
  done
  cp "$build"/sparse_data/*.vdb "$seeds/vdb/"
else
  echo "fuzz.sh: python3-zarr or python3-openvdb missing: fuzz_zarr and fuzz_vdb start unseeded" >&2
  printf '{"zarr_format": 2}' >"$seeds/zarr/empty"
  printf 'x' >"$seeds/vdb/empty"
fi
mkdir -p "$build/corpus" "$build/findings" "$build/logs"

# -malloc_limit_mb: no input may make a loader allocate more than 512 MB (every seed and
# every legal mutation stays far below; a runaway allocation is reported as a crash).
# -timeout: one input may take at most 10 s (a hang is a finding). Leaks inside the third-party
# libraries listed in tools/lsan.supp are theirs, not findings.
run_one() {
  local t="$1" corpus="$build/corpus/$1" findings="$build/findings/$1" log="$build/logs/$1.log"
  mkdir -p "$corpus" "$findings"
  LSAN_OPTIONS="suppressions=$PWD/tools/lsan.supp" nice -n 19 "$build/tests/fuzz/fuzz_$t" "$corpus" "$seeds/$t" \
    -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 -malloc_limit_mb=512 \
    -max_len=65536 -print_final_stats=1 -artifact_prefix="$findings/" >"$log" 2>&1
}

status=0
pids=()
names=()
for t in "${targets[@]}"; do
  if [[ ! -x "$build/tests/fuzz/fuzz_$t" && $t == vdb && $explicit == 0 ]]; then
    echo "fuzz.sh: fuzz_vdb skipped: splat is built without OpenVDB (SPLAT_OPENVDB)" >&2
    continue
  fi
  if [[ ! -x "$build/tests/fuzz/fuzz_$t" ]]; then
    echo "fuzz.sh: no target fuzz_$t (known: ${targets_all[*]})" >&2
    exit 2
  fi
  run_one "$t" &
  pids+=($!)
  names+=("$t")
  while [[ $(jobs -rp | wc -l) -ge $jobs ]]; do sleep 1; done
done
for i in "${!pids[@]}"; do
  t="${names[$i]}"
  if wait "${pids[$i]}"; then
    result=ok
  else
    result=FAILED
    status=1
  fi
  # libFuzzer's last status line ("#N DONE cov: C ft: F corp: ...") and its final stats.
  done_line=$(grep -E '^#[0-9]+\s+DONE' "$build/logs/$t.log" | tail -1 || true)
  execs=$(grep -E '^stat::number_of_executed_units' "$build/logs/$t.log" | awk '{print $2}' || true)
  printf 'fuzz_%-10s %-6s %s s, %s executions; %s\n' "$t" "$result" "$seconds" "${execs:-?}" \
    "${done_line:-see $build/logs/$t.log}"
  if [[ $result == FAILED ]]; then
    grep -E 'ERROR|SUMMARY|Test unit written' "$build/logs/$t.log" | head -5 >&2 || true
  fi
done
[[ $smoke == 1 && $status == 0 ]] && echo "fuzz smoke: ${#targets[@]} targets ran ${seconds} s each"
exit $status
