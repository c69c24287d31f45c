#!/usr/bin/env bash
# test_docker_packages.sh — docker/Dockerfile installs the same Debian packages
# as scripts/run (through scripts/install-deps): both must take them from
# scripts/packages.txt with the same filter, and the Dockerfile must not name
# packages of its own. Docker cannot run here, so this evaluates the two
# package-list commands as written in the files and compares the results;
# it also checks the image's required shape (Debian 12, non-root, port 8080,
# HEALTHCHECK on /healthz) and that .dockerignore keeps build folders,
# node_modules and data/samples out of the context. Prints "N passed, N failed".
set -uo pipefail
root="${SIGHTLINE_SOURCE_DIR:-$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)}"
df="$root/docker/Dockerfile"
pass=0 fail=0
check() { if eval "$1"; then pass=$((pass+1)); else fail=$((fail+1)); echo "check failed: $2" >&2; fi; }

# Joined Dockerfile (line continuations folded).
joined="$(sed -e ':a' -e '/\\$/N; s/\\\n//; ta' "$df")"

# 1. The Dockerfile's package list, evaluated with the repository's packages.txt.
docker_cmd="$(printf '%s\n' "$joined" | grep -o '\$(sed [^)]*packages\.txt[^)]*)' | head -1)"
check '[ -n "$docker_cmd" ]' "Dockerfile installs from \$(sed ... packages.txt ...)"
docker_cmd="${docker_cmd//\/opt\/sightline\/src\/scripts\/packages.txt/$root/scripts/packages.txt}"
docker_list="$(eval "echo $docker_cmd" | tr ' ' '\n' | grep -v '^$' | sort -u)"

# 2. scripts/install-deps' list, evaluated the same way.
deps_line="$(grep -o '< <(sed [^)]*packages\.txt[^)]*)' "$root/scripts/install-deps" | head -1)"
check '[ -n "$deps_line" ]' "scripts/install-deps reads packages.txt"
deps_cmd="$(printf '%s' "$deps_line" | sed -e 's/^< <[(]//' -e 's/[)]$//')"
deps_file_ref='"$here/packages.txt"'
deps_cmd="${deps_cmd/"$deps_file_ref"/$root/scripts/packages.txt}"
deps_list="$(eval "$deps_cmd" | sort -u)"

docker_count="$(printf '%s\n' "$docker_list" | grep -c .)"
check '[ "$docker_count" -ge 10 ]' "Dockerfile package list has the packages ($docker_count)"
list_diff="$(diff <(echo "$docker_list") <(echo "$deps_list") | tr '\n' ' ')"
check '[ "$docker_list" = "$deps_list" ]' "Dockerfile and scripts/install-deps install the same packages: $list_diff"
check 'grep -qx libwebsockets-dev <<<"$docker_list"' "libwebsockets-dev is in the list"
check 'grep -q "scripts/install-deps" "$root/scripts/run"' "scripts/run installs through scripts/install-deps"

# 3. No package names besides the list: strip the substitution and flags from every apt-get install.
extra=""
while IFS= read -r line; do
  rest="${line#*apt-get install}"
  rest="$(printf '%s' "$rest" | sed -e 's/\$(sed [^)]*)//' -e 's/&&.*//')"
  for w in $rest; do
    case "$w" in -*) ;; *) extra="$extra $w" ;; esac
  done
done < <(printf '%s\n' "$joined" | grep 'apt-get install')
check '[ -z "$extra" ]' "Dockerfile installs packages outside packages.txt:$extra"

# 4. Shape of the image.
check 'grep -Eq "^FROM debian:(12|bookworm)" "$df"' "Debian 12 base"
check 'grep -Eq "^EXPOSE 8080" "$df"' "EXPOSE 8080"
check 'grep -Eq "^HEALTHCHECK .*/healthz" <<<"$joined"' "HEALTHCHECK on /healthz"
check 'grep -Eq "^USER [a-z]" "$df" && ! grep -Eq "^USER root" "$df"' "runs as a non-root user"
check 'grep -q "sightline-server" "$df"' "builds and runs sightline-server"
# The build context leaves out build folders, npm modules and downloaded samples.
ign="$root/.dockerignore"
check '[ -f "$ign" ]' ".dockerignore exists at the context root"
for pat in 'build\*/' '\*\*/node_modules' 'data/samples'; do
  check "grep -qx '$pat' \"\$ign\"" ".dockerignore lists $pat"
done

echo "$pass passed, $fail failed"
[ "$fail" -eq 0 ]
