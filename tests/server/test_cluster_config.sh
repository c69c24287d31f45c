#!/usr/bin/env bash
# test_cluster_config.sh — the cluster's configuration stays one configuration:
# docker/haproxy.cfg (the compose layout) must be exactly what scripts/cluster
# generates from docker/haproxy.cfg.template for docker/compose.yaml's nodes, and
# HAProxy must accept both that file and the loopback layout scripts/cluster starts.
# Each compose node must run with the node id and agent port HAProxy expects, and
# open the one shared PostgreSQL catalog of the compose `postgres` service.
# Every node, in compose and under scripts/cluster, trusts X-Forwarded-For from the
# balancer's address only (--trusted-proxy: compose's fixed HAProxy address, 127.0.0.1
# for scripts/cluster) and keeps the default per-address cap; the balancer replaces any
# client-sent X-Forwarded-For with its own and limits connections per source.
# Containers cannot run here; this checks the files, not a running cluster
# (tests/server/test_server_cluster.c does that).
# Prints "N passed, N failed".
set -uo pipefail
root="${SIGHTLINE_SOURCE_DIR:-$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)}"
compose="$root/docker/compose.yaml"
pass=0 fail=0
check() { if eval "$1"; then pass=$((pass+1)); else fail=$((fail+1)); echo "check failed: $2" >&2; fi; }
tmp="$(mktemp -d)"; trap 'rm -rf "$tmp"' EXIT

# 1. The compose nodes: service name = --node-id = hostname, and their agent ports.
nodes="$(grep -E '^  node[0-9]+:$' "$compose" | tr -d ' :')"
check '[ "$(echo "$nodes" | wc -w)" -ge 2 ]' "compose.yaml has at least two nodeN services"
specs=()
for n in $nodes; do
  block="$(sed -n "/^  $n:\$/,/^  [a-z0-9]*:\$/p" "$compose" | sed '$d')"
  check 'grep -q "\"--node-id\", \"$n\"" <<<"$block"' "$n runs with --node-id $n"
  check 'grep -q "hostname: $n\$" <<<"$block"' "$n has hostname $n"
  agent="$(grep -o '"--agent-port", "[0-9]*"' <<<"$block" | grep -o '[0-9]*')"
  check '[ -n "$agent" ]' "$n has an --agent-port"
  check 'grep -q "\"--db\", \"postgresql://sightline@postgres:5432/sightline\"" <<<"$block"' "$n uses the shared PostgreSQL catalog"
  specs+=(--node "$n=$n:8080=${agent:-0}")
done

# The balancer's fixed address is what every node trusts, and nothing else.
proxy_ip="$(sed -n '/^  haproxy:$/,/^[a-z]/p' "$compose" | grep -o 'ipv4_address: [0-9.]*' | grep -o '[0-9.]*$')"
check '[ -n "$proxy_ip" ]' "the compose haproxy service has a fixed ipv4_address"
check 'grep -q "subnet: ${proxy_ip%.*}.0/24" "$compose"' "haproxy's address $proxy_ip lies in the compose network's subnet"
for n in $nodes; do
  block="$(sed -n "/^  $n:\$/,/^  [a-z0-9]*:\$/p" "$compose" | sed '$d')"
  check '[ "$(grep -o "\"--trusted-proxy\", \"[^\"]*\"" <<<"$block")" = "\"--trusted-proxy\", \"$proxy_ip\"" ]' \
    "$n trusts exactly the balancer's address ($proxy_ip)"
  check '! grep -q -- "--max-pending-per-address" <<<"$block"' "$n keeps the default --max-pending-per-address"
done
check 'grep -q -- "--trusted-proxy 127.0.0.1 " "$root/scripts/cluster"' "scripts/cluster's nodes trust the balancer at 127.0.0.1"
check '! grep -q -- "--max-pending-per-address [0-9]" "$root/scripts/cluster"' "scripts/cluster keeps the default --max-pending-per-address"
frontend="$(sed -n '/^frontend /,/^backend /p' "$root/docker/haproxy.cfg.template")"
check 'grep -q "http-request del-header X-Forwarded-For" <<<"$frontend" && grep -q "option forwardfor" <<<"$frontend"' \
  "the balancer replaces a client's X-Forwarded-For with its own"
check 'grep -q "tcp-request connection track-sc0 src" <<<"$frontend" && grep -q "sc0_conn_cur gt 64" <<<"$frontend" && grep -q "sc0_conn_rate gt 300" <<<"$frontend"' \
  "the balancer limits connections per source (64 open, 300 per 10 s)"

# The catalog service, and no password written into the file.
check 'grep -qE "^  postgres:\$" "$compose"' "compose.yaml has the postgres service the nodes name"
check 'grep -q "PGPASSWORD: \${SIGHTLINE_DB_PASSWORD:?" "$compose"' "the nodes' password comes from SIGHTLINE_DB_PASSWORD"
check '! grep -qE "postgresql://[^@\"]*:[^@\"]*@" "$compose"' "no password inside a --db URL"

# 2. docker/haproxy.cfg is the generated file, byte for byte.
"$root/scripts/cluster" --print-haproxy-config --bind '*' --port 8080 "${specs[@]}" >"$tmp/compose.cfg"
check 'cmp -s "$tmp/compose.cfg" "$root/docker/haproxy.cfg"' \
  "docker/haproxy.cfg differs from: scripts/cluster --print-haproxy-config --bind '*' --port 8080 ${specs[*]}"
for n in $nodes; do
  check 'grep -q "use-server $n if { urlp(session) -m beg $n. }" "$root/docker/haproxy.cfg"' "HAProxy routes $n's sessions to $n"
done

# 3. HAProxy accepts both layouts (compose names need not resolve: init-addr).
check 'haproxy -c -q -f "$root/docker/haproxy.cfg" 2>"$tmp/c1"' "haproxy -c docker/haproxy.cfg: $(cat "$tmp/c1" 2>/dev/null)"
"$root/scripts/cluster" --print-haproxy-config --port 18080 \
  --node node1=127.0.0.1:18181=18281 --node node2=127.0.0.1:18182=18282 >"$tmp/loop.cfg"
check 'haproxy -c -q -f "$tmp/loop.cfg" 2>"$tmp/c2"' "haproxy -c of the loopback layout: $(cat "$tmp/c2" 2>/dev/null)"
check 'grep -q "bind 127.0.0.1:18080" "$tmp/loop.cfg"' "the loopback layout binds 127.0.0.1"

# 4. Bad arguments are refused.
check '! "$root/scripts/cluster" --nodes 0 >/dev/null 2>&1' "--nodes 0 refused"
check '! "$root/scripts/cluster" --nodes x >/dev/null 2>&1' "--nodes x refused"
check '! "$root/scripts/cluster" --print-haproxy-config >/dev/null 2>&1' "--print-haproxy-config without nodes refused"

echo "$pass passed, $fail failed"
[ "$fail" = 0 ]
