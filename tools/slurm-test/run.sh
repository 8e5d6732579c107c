#!/usr/bin/env bash
# Starts a one-node Slurm cluster on this machine (MUNGE, slurmctld and slurmd, with a
# configuration made for the test, everything under a scratch directory) and runs the
# Slurm executor's tests against it (crates/harness/tests/slurm.rs, ignored by a plain
# `cargo test`). Needs root (the daemons run as root) and Debian's `slurm-wlm` and `munge`
# packages (`.ci/run` installs them). Fails, saying why, when the cluster cannot start:
# it never skips. Usage: tools/slurm-test/run.sh (from anywhere in the workspace).
set -euo pipefail
cd "$(dirname "$0")/../.."

fail() { echo "slurm-test: $*" >&2; exit 1; }
[ "$(id -u)" -eq 0 ] || fail "needs root to start munged, slurmctld and slurmd (running as $(id -un))"
for program in munged slurmctld slurmd sbatch squeue scontrol scancel sinfo; do
  command -v "$program" >/dev/null || fail "\`$program\` is not installed (apt-get install slurm-wlm munge)"
done

dir=$(mktemp -d /tmp/meniscus-slurm.XXXXXX)
cleanup() {
  local pids=()
  for file in "$dir"/*.pid "$dir"/munge/munged.pid; do
    [ -f "$file" ] && pids+=("$(cat "$file")")
  done
  for pid in "${pids[@]}"; do kill "$pid" 2>/dev/null || true; done
  # The daemons write their state while they stop: wait for them before removing it.
  for _ in $(seq 1 50); do
    alive=0
    for pid in "${pids[@]}"; do kill -0 "$pid" 2>/dev/null && alive=1; done
    [ "$alive" -eq 0 ] && break
    sleep 0.2
  done
  rm -rf "$dir" 2>/dev/null || true
}
trap cleanup EXIT
mkdir -p "$dir"/{state,spool,log,munge}
chmod 700 "$dir/munge"
head -c 1024 /dev/urandom > "$dir/munge/munge.key"
chmod 400 "$dir/munge/munge.key"
socket="$dir/munge/munge.socket"
munged --force --key-file="$dir/munge/munge.key" --socket="$socket" \
  --log-file="$dir/munge/munged.log" --pid-file="$dir/munge/munged.pid" \
  --seed-file="$dir/munge/munged.seed" || fail "munged did not start: $(cat "$dir/munge/munged.log" 2>/dev/null)"

host=$(hostname -s)
export SLURM_CONF="$dir/slurm.conf"
sed -e "s|@DIR@|$dir|g" -e "s|@HOST@|$host|g" -e "s|@CPUS@|$(nproc)|g" -e "s|@SOCKET@|$socket|g" \
  tools/slurm-test/slurm.conf > "$SLURM_CONF"
slurmctld -f "$SLURM_CONF" || fail "slurmctld did not start: $(tail -n 5 "$dir/log/slurmctld.log" 2>/dev/null)"
slurmd -f "$SLURM_CONF" || fail "slurmd did not start: $(tail -n 5 "$dir/log/slurmd.log" 2>/dev/null)"
for _ in $(seq 1 30); do
  state=$(sinfo -h -p debug -o %t 2>/dev/null || true)
  [ "$state" = "idle" ] && break
  sleep 1
done
[ "$state" = "idle" ] || fail "the node did not come up (state \`$state\`): $(tail -n 5 "$dir/log/slurmd.log" "$dir/log/slurmctld.log")"
echo "slurm-test: one-node cluster up on $host ($(sinfo --version))"

# The tasks run this build's meniscus binary (the tests check its solver fingerprint), the
# one `cargo test --workspace` builds for the command line's tests: the same command builds
# it here (nothing to do after the README's test command; a plain `cargo build` would
# resolve other features and rebuild the dependencies).
cargo test --quiet --workspace --no-run
MENISCUS_BIN="$(pwd)/target/debug/meniscus" \
  cargo test --workspace --test slurm -- --ignored --test-threads=1
