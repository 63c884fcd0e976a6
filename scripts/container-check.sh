#!/usr/bin/env bash
# The image and the compose file under a real container engine (podman), against the host:
#   sudo scripts/container-check.sh [SCENARIO_FILE] [DURATION_S]   (deploy/traffic.json, 5 s)
# 1. a base image: python:3.11-slim from a registry when one answers, else a local one made
#    with debootstrap (Debian bookworm's python3 is 3.11) as localhost/python:3.11-slim;
# 2. the image from deploy/Dockerfile (pip downloads the wheels from PyPI);
# 3. `catabot deploy compose SCENARIO` and every service of that compose file as a container,
#    in dependency order, each started when what it depends on is healthy by its own
#    healthcheck (scripts/compose_podman.py reads the YAML; host network, a free port):
#    plain, then the secure variant (a `catabot secure init` profile: TLS, a login each);
# 4. the same with an external participant that never joins: named, exit 1;
# 5. both files under podman-compose (from PyPI, in a venv here): a podman network, the
#    router reached by its name (the secure one by its certificate's, an alias), `run --rm
#    conductor` as a user would (podman 4.3 has no health conditions: it ignores them);
# 6. the scenario with `catabot run` on the host, and the recorded CSV and MCAP files of the
#    four container runs compared with its byte for byte (same scenario and seed: same bytes).
# Needs root, podman, runc and debootstrap (apt-get install podman runc debootstrap) and a
# Python with CataBot and pyyaml (PYTHON, default .venv/bin/python). Takes minutes; CI runs
# the structural test of the compose file instead (tests/catabot/run/test_compose.py).
set -euo pipefail
repo=$(cd "$(dirname "$0")/.." && pwd)
scenario=$(realpath "${1:-$repo/deploy/traffic.json}")
duration=${2:-5}
py=${PYTHON:-$repo/.venv/bin/python}
work=${CHECK_DIR:-/var/tmp/catabot-container-check}
image=${CATABOT_IMAGE:-localhost/catabot:check}
base=${BASE:-}
podman=(podman --runtime runc)
run_flags=(--network host --ulimit nofile=1024:1024 --ulimit nproc=1024:1024)
export PYTHONPATH="$repo${PYTHONPATH:+:$PYTHONPATH}"
say() { printf '\n== %s\n' "$*"; }

[ "$(id -u)" = 0 ] || { echo "container-check: needs root (podman with runc, debootstrap)" >&2; exit 2; }
for tool in podman runc debootstrap; do
  command -v "$tool" >/dev/null || { echo "container-check: $tool is missing" >&2; exit 2; }
done
mkdir -p "$work"

local_base() {  # a python:3.11-slim stand-in: Debian bookworm minbase + python3, pip, venv
  local tag=localhost/python:3.11-slim root="$work/rootfs"
  if "${podman[@]}" image exists "$tag"; then echo "$tag"; return; fi
  rm -rf "$root"
  debootstrap --variant=minbase --include=python3,python3-pip,python3-venv,ca-certificates \
    bookworm "$root" http://deb.debian.org/debian >"$work/debootstrap.log" 2>&1
  rm -f "$root"/usr/lib/python3.*/EXTERNALLY-MANAGED      # pip installs system-wide, as in
  ln -sf python3 "$root/usr/bin/python"                     # the official image
  # This host's certificate authorities (a proxy may intercept TLS on the way to PyPI).
  cp /etc/ssl/certs/ca-certificates.crt "$root/etc/ssl/certs/ca-certificates.crt"
  rm -rf "$root"/var/lib/apt/lists/* "$root"/var/cache/apt/archives/*.deb
  tar -C "$root" -c . | "${podman[@]}" import --change 'CMD ["python3"]' - "$tag" \
    >/dev/null 2>>"$work/debootstrap.log"
  rm -rf "$root"
  echo "$tag"
}

say "base image"
if [ -z "$base" ]; then
  if timeout 30 "${podman[@]}" pull -q docker.io/library/python:3.11-slim >/dev/null 2>&1; then
    base=docker.io/library/python:3.11-slim
  else
    echo "no registry answers: a local base from debootstrap"
    base=$(local_base)
  fi
fi
echo "base: $base"

say "build $image"
start=$(date +%s)
"${podman[@]}" build --pull=never --network host --build-arg "BASE=$base" \
  -f "$repo/deploy/Dockerfile" -t "$image" "$repo" >"$work/build.log" 2>&1 \
  || { tail -n 30 "$work/build.log"; exit 1; }
echo "built in $(( $(date +%s) - start )) s; $("${podman[@]}" image inspect "$image" --format '{{.Size}}' | numfmt --to=iec) "
"${podman[@]}" run --rm "${run_flags[@]}" --entrypoint python "$image" -c \
  "import dartpy, open3d, zenoh, rerun; print('the image loads dartpy', dartpy.__version__, 'and open3d', open3d.__version__)"
"${podman[@]}" run --rm "${run_flags[@]}" "$image" scenario validate harbour  # its terrain PNG
# Every shared library a wheel loads is in the image (open3d's TensorFlow/PyTorch ops aside,
# and numba's TBB threading layer: loaded only for a numba-parallel kernel, and CataBot has
# none, wave_pass.py deals its chunks to threads of its own).
missing=$("${podman[@]}" run --rm "${run_flags[@]}" --entrypoint bash "$image" -c \
  'find / -xdev -path "*-packages/*" -name "*.so*" | while read -r f; do ldd "$f" 2>/dev/null |
   grep "not found" | sed "s|^|$(basename "$f"):|"; done' |
  grep -v -E '^(open3d_(tf|torch)_ops|tbbpool\.)' || true)
[ -z "$missing" ] || { echo "libraries missing in the image:"; echo "$missing"; exit 1; }
echo "every shared library the wheels link is in the image"

say "scenario $scenario, $duration s"
rm -rf "$work/scenario" "$work/runs" "$work/host" "$work/logs" "$work/secure"
mkdir -p "$work/scenario" "$work/runs" "$work/host" "$work/logs"
"$py" - "$scenario" "$duration" "$work/scenario" <<'EOF'
import json, sys
data = json.load(open(sys.argv[1]))
data["duration_s"] = float(sys.argv[2])
open(f"{sys.argv[3]}/scenario.json", "w").write(json.dumps(data, indent=2) + "\n")
data["clock"] = dict(data.get("clock", {}), external_participants=["stack"])
open(f"{sys.argv[3]}/stack.json", "w").write(json.dumps(data, indent=2) + "\n")
EOF
export CATABOT_IMAGE=$image CATABOT_RUNS=$work/runs

containers() {  # VARIANT SCENARIO [compose flags]: its compose file's services as containers
  local variant=$1 file=$2 status=0 start; shift 2
  "$py" -m catabot deploy compose "$file" -o "$work/$variant.yml" "$@" >/dev/null
  grep -E '^  (services|external|secure):' "$work/$variant.yml"
  mkdir -p "$work/logs/$variant"
  start=$(date +%s)
  CATABOT_RUN=$variant "$py" "$repo/scripts/compose_podman.py" "$work/$variant.yml" \
    --prefix "cbcheck$$-$variant" --logs "$work/logs/$variant" -- "${podman[@]}" || status=$?
  echo "containers: exit $status in $(( $(date +%s) - start )) s (logs: $work/logs/$variant)"
  grep -h '"kind": "result"' "$work/logs/$variant/conductor.log" | cut -c1-160
  return "$status"
}

port=$("$py" -c 'from catabot.bus.session import free_port; print(free_port())')
say "plain: the compose services as containers, router on tcp/127.0.0.1:$port"
export CATABOT_LISTEN=tcp/127.0.0.1:$port CATABOT_ROUTER=tcp/127.0.0.1:$port
containers plain "$work/scenario/scenario.json" || { tail -n 5 "$work"/logs/plain/*.log; exit 1; }

say "secure: a catabot secure init profile, TLS and a login per container"
"$py" -m catabot secure init "$work/secure" --host catabot-router --port "$port" | sed -n 1p  # reads it all: no broken pipe under pipefail
export CATABOT_LISTEN=tls/127.0.0.1:$port CATABOT_ROUTER=tls/localhost:$port  # in its certificate
containers secure "$work/scenario/scenario.json" --secure "$work/secure" \
  || { tail -n 5 "$work"/logs/secure/*.log; exit 1; }

say "a participant that never joins: named after CATABOT_START_TIMEOUT, exit 1"
export CATABOT_LISTEN=tcp/127.0.0.1:$port CATABOT_ROUTER=tcp/127.0.0.1:$port
if CATABOT_START_TIMEOUT=3 containers missing "$work/scenario/stack.json"; then
  echo "container-check: FAIL (the conductor did not fail without the stack)"; exit 1
fi
grep -q 'never joined within 3 s: stack' "$work/logs/missing/conductor.log" \
  || { echo "container-check: FAIL (the missing participant is not named)"; exit 1; }

say "compose: both files under podman-compose (PyPI), a podman network, the router by name"
[ -x "$work/pc/bin/podman-compose" ] || { python3 -m venv "$work/pc" \
  && "$work/pc/bin/pip" install -q podman-compose >"$work/pc.log" 2>&1; }
"$work/pc/bin/podman-compose" --version | sed -n 1p
unset CATABOT_LISTEN CATABOT_ROUTER  # the files' defaults: the router's name in the network
compose() {  # VARIANT ARGS...: podman-compose on $work/VARIANT.yml
  local variant=$1; shift
  CATABOT_RUN=compose-$variant CATABOT_PORT=$port "$work/pc/bin/podman-compose" \
    --podman-args="--runtime runc" -p "cbcheck$$$variant" -f "$work/$variant.yml" \
    --podman-run-args="--ulimit nofile=1024:1024 --ulimit nproc=1024:1024" "$@"
}
for variant in plain secure; do
  status=0
  compose "$variant" run --rm conductor >"$work/logs/compose-$variant.log" 2>&1 || status=$?
  compose "$variant" down >/dev/null 2>&1 || true
  grep -h '"kind": "result"' "$work/logs/compose-$variant.log" | cut -c1-120
  echo "$variant: podman-compose run --rm conductor: exit $status"
  [ "$status" = 0 ] || { tail -n 20 "$work/logs/compose-$variant.log"; exit 1; }
done

say "the same scenario on the host (catabot run)"
"$py" -m catabot run "$work/scenario/scenario.json" --out "$work/host" --quiet | tail -n 2
host_run=$(ls -d "$work/host"/*/)

say "recorded bytes, containers against host"
fail=0
for variant in plain secure compose-plain compose-secure; do
  cd "$work/runs/$variant"
  files=$(ls ./*.csv ./*.mcap)
  for f in $files; do
    cmp -s "$f" "$host_run/$f" || { echo "DIFFERENT  $variant/$f"; fail=1; }
  done
  for f in "$host_run"/*.csv "$host_run"/*.mcap; do
    [ -e "$(basename "$f")" ] || { echo "MISSING in $variant: $(basename "$f")"; fail=1; }
  done
  # shellcheck disable=SC2086
  echo "$variant: $(echo "$files" | wc -w) files, $(cat $files | wc -c) bytes, compared with the host's"
done
[ "$fail" = 0 ] && echo "container-check: PASS (4 container runs byte-identical to the host's)" \
  || { echo "container-check: FAIL"; exit 1; }
