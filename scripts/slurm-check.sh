#!/usr/bin/env bash
# Evaluation on a real Slurm: starts a one-node Slurm on this machine (munged, slurmctld and
# slurmd, with their own keys, configuration, state and logs under a temporary directory, on
# ports of their own), renders a set of recordings, evaluates them as a Slurm array job with
# `evaluate --shard I/N --resume` followed by one gathering `--resume` run, and checks that
# what it wrote is what one process writes (timings aside). Everything is stopped and removed
# at the end, whatever happened.
#
#   scripts/slurm-check.sh [--oalservo PATH] [--tasks N] [--inputs N] [--no-install] [--keep]
#
# Debian's slurm-wlm and munge are installed when missing (scripts/install-deps.sh), unless
# --no-install: then a machine without them is skipped with exit code 77 and the reason
# (ctest's slurm-check test). Exit 0: identical; 1: different or a step failed (its log shown).
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)

oalservo="$here/build/app/oalservo"
tasks=3
inputs=5
install=1
keep=0
usage() { sed -n '9p' "$0" | sed 's/^#   //' >&2; }
while [ $# -gt 0 ]; do
  case "$1" in
    --oalservo) oalservo="$2"; shift 2 ;;
    --tasks) tasks="$2"; shift 2 ;;
    --inputs) inputs="$2"; shift 2 ;;
    --no-install) install=0; shift ;;
    --keep) keep=1; shift ;;
    -h|--help) usage; exit 0 ;;
    *) echo "slurm-check: unknown option '$1'" >&2; usage; exit 2 ;;
  esac
done
for count in "$tasks" "$inputs"; do
  if ! [[ "$count" =~ ^[1-9][0-9]*$ ]]; then
    echo "slurm-check: --tasks and --inputs take a whole number >= 1, not '$count'" >&2
    exit 2
  fi
done
if [ ! -x "$oalservo" ]; then
  echo "slurm-check: no oalservo executable at $oalservo (build first: scripts/build.sh," \
       "or give --oalservo PATH)" >&2
  exit 2
fi

daemons=(munged slurmctld slurmd sbatch sinfo scontrol)
missing_tools() {
  local tool missing=()
  for tool in "${daemons[@]}"; do
    command -v "$tool" > /dev/null 2>&1 || [ -x "/usr/sbin/$tool" ] || missing+=("$tool")
  done
  echo "${missing[*]}"
}
if [ -n "$(missing_tools)" ]; then
  if [ "$install" -eq 0 ]; then
    echo "slurm-check: skipped: Slurm is not installed (missing: $(missing_tools));" \
         "scripts/slurm-check.sh installs Debian's slurm-wlm and munge" >&2
    exit 77
  fi
  "$here/scripts/install-deps.sh" slurm-wlm munge
fi
export PATH="$PATH:/usr/sbin"
if [ "$(id -u)" -ne 0 ]; then
  # slurmd starts each job as its owner, which takes root.
  echo "slurm-check: skipped: slurmd must run as root to start jobs (run as root or under sudo)" >&2
  exit 77
fi

work=$(mktemp -d /tmp/oal-slurm-check.XXXXXX)
chmod 711 "$work"  # munged wants every directory above its socket searchable
slurm_conf="$work/slurm.conf"
export SLURM_CONF="$slurm_conf"
munge_socket="$work/munge/munge.socket"

stop() {
  local status=$?
  if [ -f "$work/slurmctld.pid" ]; then scontrol shutdown > /dev/null 2>&1 || true; fi
  for pid_file in "$work/slurmd.pid" "$work/slurmctld.pid"; do
    if [ -f "$pid_file" ]; then
      local pid
      pid=$(cat "$pid_file")
      for _ in $(seq 50); do kill -0 "$pid" 2> /dev/null || break; sleep 0.1; done
      kill "$pid" 2> /dev/null || true
    fi
  done
  [ -S "$munge_socket" ] && munged --stop --socket="$munge_socket" > /dev/null 2>&1 || true
  if [ "$keep" -eq 1 ]; then
    echo "slurm-check: kept $work"
  else
    rm -rf "$work"
  fi
  exit "$status"
}
trap stop EXIT
trap 'exit 1' INT TERM

# A step that failed: what it said, the daemons' logs, exit 1 (stop() cleans up).
fail() {
  echo "slurm-check: $1" >&2
  for log in "$work"/log/*.log "$work"/jobs/*.out; do
    [ -s "$log" ] || continue
    echo "---- ${log#$work/} (last 20 lines)" >&2
    tail -n 20 "$log" >&2
  done
  exit 1
}

echo "slurm-check: one-node Slurm under $work"
mkdir -p "$work/munge" "$work/state" "$work/spool" "$work/log" "$work/jobs"
chmod 700 "$work/munge"
head -c 1024 /dev/urandom > "$work/munge/munge.key"
chmod 400 "$work/munge/munge.key"
munged --force --key-file="$work/munge/munge.key" --socket="$munge_socket" \
  --pid-file="$work/munge/munged.pid" --seed-file="$work/munge/munged.seed" \
  --log-file="$work/log/munged.log" || fail "munged did not start"

# Ports of our own, away from a Slurm the machine may already run (6817, 6818).
port=$((20000 + ($$ % 20000) * 2))
node=$(hostname -s)
user=$(id -un)
cat > "$slurm_conf" << EOF
ClusterName=oalcheck
SlurmctldHost=$node
SlurmUser=$user
SlurmdUser=root
SlurmctldPort=$port
SlurmdPort=$((port + 1))
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$munge_socket
StateSaveLocation=$work/state
SlurmdSpoolDir=$work/spool
SlurmctldPidFile=$work/slurmctld.pid
SlurmdPidFile=$work/slurmd.pid
SlurmctldLogFile=$work/log/slurmctld.log
SlurmdLogFile=$work/log/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SwitchType=switch/none
MpiDefault=none
SchedulerType=sched/builtin
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
ReturnToService=2
JobCompType=jobcomp/none
AccountingStorageType=accounting_storage/none
JobAcctGatherType=jobacct_gather/none
InactiveLimit=0
MinJobAge=300
KillWait=5
NodeName=$node NodeAddr=127.0.0.1 CPUs=$(nproc) State=UNKNOWN
PartitionName=check Nodes=$node Default=YES MaxTime=INFINITE State=UP
EOF
slurmctld -i -f "$slurm_conf" || fail "slurmctld did not start"
slurmd -f "$slurm_conf" || fail "slurmd did not start"
for _ in $(seq 100); do
  state=$(sinfo -h -n "$node" -o %T 2> /dev/null || true)
  [ "$state" = "idle" ] && break
  sleep 0.2
done
[ "$state" = "idle" ] || fail "the node did not come up (its state: '${state:-none}')"
echo "slurm-check: node $node idle, $(nproc) CPUs, ports $port and $((port + 1))"

# The recordings: rendered scripted sequences of the A3 sheet and the board, each with its
# truth, camera.xml and target.yaml beside the frames.
sequences=(slow occlusion fast illumination)
targets=(four-line-a3 four-line-board)
mkdir -p "$work/recordings"
for ((i = 0; i < inputs; ++i)); do
  "$oalservo" render --sequence "${sequences[i % ${#sequences[@]}]}" \
    --target "${targets[i % ${#targets[@]}]}" --count 10 --seed $((i + 1)) \
    --out "$work/recordings/input-$i" > "$work/log/render-$i.log" 2>&1 ||
    fail "render of input $i failed: $(tail -n 3 "$work/log/render-$i.log")"
done

evaluate=("$oalservo" evaluate "$work/recordings" --jobs 1)
echo "slurm-check: $inputs recordings; one process ..."
"${evaluate[@]}" --out "$work/single" > "$work/log/single.log" 2>&1 ||
  fail "evaluate in one process failed: $(tail -n 3 "$work/log/single.log")"

echo "slurm-check: an array job of $tasks tasks (--shard I/$tasks --resume), then a gathering run ..."
printf -v quoted '%q ' "${evaluate[@]}"
array=$(sbatch --parsable --job-name=oal-evaluate --array=0-$((tasks - 1)) \
  --output="$work/jobs/shard-%a.out" --chdir="$work" \
  --wrap "$quoted --shard \${SLURM_ARRAY_TASK_ID}/$tasks --resume --out $work/sharded") ||
  fail "sbatch of the array job was refused"
# afterok: the gathering job runs only when every shard succeeded; a failed shard cancels it
# (--kill-on-invalid-dep) and sbatch --wait returns non-zero.
sbatch --parsable --wait --job-name=oal-gather --dependency="afterok:$array" \
  --kill-on-invalid-dep=yes --output="$work/jobs/gather.out" --chdir="$work" \
  --wrap "$quoted --resume --out $work/sharded" > /dev/null ||
  fail "the array job $array or its gathering run failed"
shards_ran=$(grep -l "evaluated" "$work"/jobs/shard-*.out 2> /dev/null | wc -l)
[ "$shards_ran" -eq "$tasks" ] || fail "$shards_ran of $tasks array tasks said what they evaluated"
grep -q "resumed" "$work/jobs/gather.out" ||
  fail "the gathering run evaluated again what the shards had done"

# Each task wrote its own index and run record beside the gathered ones (index-I-of-N.html,
# run-I-of-N.json): one per task, and nothing else differs.
for ((task = 0; task < tasks; ++task)); do
  for own in "index-$task-of-$tasks.html" "run-$task-of-$tasks.json"; do
    [ -f "$work/sharded/$own" ] || fail "array task $task did not write its $own"
  done
done

# What both wrote, timings aside (timing.json, timing.jsonl, the reports' timing block), and
# but for the tasks' own records.
normalise() {
  local tree=$1 out=$2
  (cd "$tree" && find . -type f ! -name timing.json ! -name timing.jsonl \
     ! -name 'index-*-of-*.html' ! -name 'run-*-of-*.json' | LC_ALL=C sort) |
    while read -r file; do
      local hash
      if [[ "$file" == *.html ]]; then
        hash=$(perl -0pe 's{<script type="application/json" id="oal-timing">[^<]*</script>}{}g' \
          "$tree/$file" | sha256sum)
      else
        hash=$(sha256sum < "$tree/$file")
      fi
      echo "${hash%% *} $file"
    done > "$out"
}
normalise "$work/single" "$work/single.sums"
normalise "$work/sharded" "$work/sharded.sums"
files=$(wc -l < "$work/single.sums")
if ! diff "$work/single.sums" "$work/sharded.sums" > "$work/log/diff.log"; then
  fail "the sharded evaluation differs from one process's (< one process, > sharded):
$(grep '^[<>]' "$work/log/diff.log" | head -n 40)"
fi
echo "slurm-check: identical: the $files files $tasks array tasks and the gathering run wrote" \
     "are those one process writes (timings aside)"
