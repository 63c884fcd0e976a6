#!/usr/bin/env bash
# Two "machines" on one box (Linux network namespaces, needs root): host A runs the router and
# the conductor, host B runs physics, sensors and the recorder; they talk only over a veth link.
# The same commands as deploy/docker-compose.yml, as processes.
#   sudo deploy/two-hosts.sh SCENARIO OUT_DIR
set -euo pipefail
scenario=$(realpath "$1"); out=$(realpath -m "$2"); mkdir -p "$out"
py=${PYTHON:-$(command -v python3)}
A=cbhostA$$; B=cbhostB$$; VA=cbva$$; VB=cbvb$$
cleanup() {
  ip netns pids "$A" 2>/dev/null | xargs -r kill 2>/dev/null || true
  ip netns pids "$B" 2>/dev/null | xargs -r kill 2>/dev/null || true
  ip netns del "$A" 2>/dev/null || true; ip netns del "$B" 2>/dev/null || true
}
trap cleanup EXIT
ip netns add "$A"; ip netns add "$B"
ip link add "$VA" type veth peer name "$VB"
ip link set "$VA" netns "$A"; ip link set "$VB" netns "$B"
ip -n "$A" addr add 10.203.0.1/24 dev "$VA"; ip -n "$B" addr add 10.203.0.2/24 dev "$VB"
for ns in "$A" "$B"; do ip -n "$ns" link set lo up; done
ip -n "$A" link set "$VA" up; ip -n "$B" link set "$VB" up
router=tcp/10.203.0.1:7447
flags=(--scenario "$scenario" --connect "$router" --mode client)
ip netns exec "$A" "$py" -m catabot router --listen "$router" >"$out/router.log" 2>&1 &
sleep 1
for svc in physics sensors recorder; do
  ip netns exec "$B" "$py" -m catabot service "$svc" "${flags[@]}" --run-dir "$out" \
    >"$out/$svc.log" 2>&1 &
done
ip netns exec "$A" "$py" -m catabot service conductor "${flags[@]}" >"$out/conductor.out" \
  2>"$out/conductor.log"
status=$?
sleep 2
tail -n 1 "$out/conductor.out"
exit $status
