#!/usr/bin/env bash
# Every CataBot process on a host of its own (Linux network namespaces on one box, needs root),
# laid out as deploy/docker-compose.yml lays out its containers: a router, then the conductor
# and each service the scenario runs, each with its own address on one switch (a bridge), all
# talking through the router. Optionally break the network mid-run, as a real fleet does:
#   sudo deploy/hosts.sh SCENARIO OUT_DIR                     # a run across six hosts
#   sudo deploy/hosts.sh SCENARIO OUT_DIR --cut physics 4     # unplug physics' cable after 4 s
#   sudo deploy/hosts.sh SCENARIO OUT_DIR --kill sensors 4    # power sensors' host off after 4 s
# Prints each host's address, the conductor's last line (its result: the error names a lost
# participant) and, for a fault, `fault <kind> <service> at <unix time>`; exits with the
# conductor's status. Logs and the run folder go to OUT_DIR.
set -euo pipefail
usage="usage: $0 SCENARIO OUT_DIR [--cut|--kill SERVICE AFTER_S]"
[[ $# -ge 2 ]] || { echo "$usage" >&2; exit 2; }
[[ -f $1 ]] || { echo "$0: no scenario file $1 (give a path: deploy/scenario.json)" >&2; exit 2; }
scenario=$(realpath "$1"); out=$(realpath -m "$2"); shift 2
fault=""; victim=""; after=0
if [[ $# -gt 0 ]]; then
  [[ $# -eq 3 && ( $1 == --cut || $1 == --kill ) ]] || {
    echo "$usage" >&2; exit 2; }
  fault=${1#--}; victim=$2; after=$3
fi
repo_py="$(cd "$(dirname "$0")/.." && pwd)/.venv/bin/python"  # sudo's python3 has no catabot
py=${PYTHON:-$([[ -x $repo_py ]] && echo "$repo_py" || command -v python3)}
"$py" -c "import catabot" 2>/dev/null || {
  echo "$0: $py cannot import catabot: run make setup, or give PYTHON=/path/to/venv/bin/python" >&2
  exit 2; }
tag=$$; sw=cbsw$tag; bridge=cbbr$tag
# The services this scenario runs, as `catabot run` would start them (the world's participants
# that are CataBot services; an external stack joins through the router like any client).
mapfile -t lines < <("$py" - "$scenario" <<'EOF'
import sys
from catabot.config.load import load_scenario
from catabot.config.scenario import services
from catabot.config.sensors import service_of
names = [s for s in services(load_scenario(sys.argv[1])) if s != "conductor"]
for name in names:  # a shard (`sensors.1` of 4) runs as `catabot service sensors --shard 1/4`
    program, shard = service_of(name, names)
    print(name, program, *shard)
EOF
)
services=(); declare -A command
for line in "${lines[@]}"; do
  read -r name rest <<<"$line"; services+=("$name"); command[$name]=$rest
done
hosts=(router conductor "${services[@]}")
[[ -z $victim || " ${services[*]} " == *" $victim "* ]] || {
  echo "no service $victim in this scenario (it runs: ${services[*]})" >&2; exit 2; }
mkdir -p "$out"   # only once the arguments are good: a refused call leaves no folder

ns() { echo "cb${1//./}$tag" | cut -c1-15; }   # namespace names: <= 15 characters
pids() { for h in "$@"; do ip netns pids "$(ns "$h")" 2>/dev/null || true; done; }
cleanup() {  # stopped early (Ctrl-C, SIGTERM): the conductor ends the run, files whole
  pids conductor | xargs -r kill -TERM 2>/dev/null || true
  for _ in $(seq 100); do [[ -z $(pids "${hosts[@]:1}") ]] && break; sleep 0.1; done
  for h in "${hosts[@]}"; do
    ip netns pids "$(ns "$h")" 2>/dev/null | xargs -r kill -9 2>/dev/null || true
    ip netns del "$(ns "$h")" 2>/dev/null || true
  done
  ip netns del "$sw" 2>/dev/null || true
}
trap cleanup EXIT
trap 'exit 130' INT; trap 'exit 143' TERM   # either way through cleanup
ip netns add "$sw"
ip -n "$sw" link add "$bridge" type bridge
ip -n "$sw" link set "$bridge" up
i=0
for h in "${hosts[@]}"; do
  i=$((i + 1)); n=$(ns "$h")
  ip netns add "$n"
  ip link add "p$i.$tag" type veth peer name eth0 netns "$n"
  ip link set "p$i.$tag" netns "$sw"
  ip -n "$sw" link set "p$i.$tag" master "$bridge" up
  ip -n "$n" addr add "10.203.0.$i/24" dev eth0
  ip -n "$n" link set eth0 up; ip -n "$n" link set lo up
  echo "host $h 10.203.0.$i"
done
router=tcp/10.203.0.1:7447
flags=(--scenario "$scenario" --connect "$router" --mode client)
(ip netns exec "$(ns router)" "$py" -m catabot router --listen "$router" >"$out/router.log" 2>&1 &)
for _ in $(seq 100); do   # the router's port open, seen from the conductor's host
  ip netns exec "$(ns conductor)" bash -c 'echo >/dev/tcp/10.203.0.1/7447' 2>/dev/null && break
  sleep 0.1
done
for svc in "${services[@]}"; do
  # shellcheck disable=SC2086  # the service and its --shard: words on purpose
  (ip netns exec "$(ns "$svc")" "$py" -m catabot service ${command[$svc]} "${flags[@]}" --run-dir "$out" \
    >"$out/$svc.log" 2>&1 &)   # not this shell's jobs: no "Killed" lines at the clean-up
done
ip netns exec "$(ns conductor)" "$py" -m catabot service conductor "${flags[@]}" \
  >"$out/conductor.out" 2>"$out/conductor.log" &
conductor=$!
if [[ -n $fault ]]; then
  # Wait for the run to tick (the conductor's first progress line), then break it.
  until grep -q '"progress"' "$out/conductor.out" 2>/dev/null || ! kill -0 $conductor 2>/dev/null
  do sleep 0.1; done
  sleep "$after"
  port=p$(( $(printf '%s\n' "${hosts[@]}" | grep -nx "$victim" | cut -d: -f1) )).$tag
  if [[ $fault == cut ]]; then
    ip -n "$sw" link set "$port" down   # silent: no FIN, no RST, the host keeps running
  else
    ip netns pids "$(ns "$victim")" | xargs -r kill -9
  fi
  echo "fault $fault $victim at $(date +%s.%N)"
fi
status=0; wait $conductor || status=$?
echo "conductor ended at $(date +%s.%N)"
# Every service ends by itself: on the conductor's End, or, cut off from the router, once its
# link lease runs out and it finds itself orphaned; both flush their files. Wait for that.
for _ in $(seq 100); do
  alive=$(for s in "${services[@]}"; do ip netns pids "$(ns "$s")"; done | wc -l)
  [[ $alive -eq 0 ]] && break
  sleep 0.1
done
[[ $alive -eq 0 ]] || echo "killed after 10 s: $alive processes that did not end" >&2
tail -n 1 "$out/conductor.out"
exit $status
