#!/usr/bin/env bash
# Run the workflow through a real one-node SLURM cluster on localhost and check
# that its outputs equal a local run's.  As root on Debian, venv active:
#
#     bash tests/cluster/slurm_local.sh [TARGET ...]
#
# TARGET defaults to `paper` when the workflow has that rule, else
# figures/fig06_single_coarse.png.  Steps: install slurmctld, slurmd,
# slurm-client, slurmdbd, munge and mariadb-server from Debian (if missing);
# start munged, a private MariaDB, slurmdbd, slurmctld and slurmd, all with
# files under one temporary directory and ports 16306/16817-16819; clone HEAD
# twice; run TARGET locally (-c2) in one clone and with
#     snakemake --profile tests/cluster/profile --workflow-profile workflow/profiles/slurm TARGET
# in the other; check with sacct that every job ran as a COMPLETED SLURM job;
# compare the outputs (tests/cluster/compare_outputs.py); stop every daemon it
# started (by pid) and remove its pid files.  Committed code only (HEAD).
# Exit status: 0 passed, 1 failed, 77 cannot run here (the reason is printed).
# KEEP=1 keeps the temporary directory (logs, both clones).
set -euo pipefail

skip() { echo "SKIP: $*" >&2; exit 77; }
log() { echo "[slurm_local $(date +%T)] $*" >&2; }

ROOT=$(git -C "$(dirname "$0")" rev-parse --show-toplevel)
PY=$(command -v python || command -v python3)
[ "$(id -u)" = 0 ] || skip "needs root (installs packages and starts SLURM daemons)"
command -v apt-get >/dev/null || skip "needs apt-get (Debian) to install SLURM"
"$PY" -c "import snakemake_executor_plugin_slurm" 2>/dev/null ||
    skip "$PY has no snakemake-executor-plugin-slurm (pip install -r requirements/lock-py311.txt)"
for port in 16306 16817 16818 16819; do
    ! (exec 3<>"/dev/tcp/127.0.0.1/$port") 2>/dev/null || skip "port $port is in use (another test cluster?)"
done

PKGS="slurmctld slurmd slurm-client slurmdbd munge mariadb-server"
if ! dpkg -s $PKGS >/dev/null 2>&1; then
    log "installing $PKGS"
    apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq $PKGS >/dev/null ||
        skip "apt-get install $PKGS failed"
fi

# srun inside a job reads the default /etc/slurm/slurm.conf: the jobstep plugin
# drops every SLURM_* variable (SLURM_CONF too) before calling it.  A link to
# this cluster's file is put there for the run and removed afterwards.
[ ! -e /etc/slurm/slurm.conf ] || skip "/etc/slurm/slurm.conf exists (a real cluster here?); not touching it"

WORK=$(mktemp -d /tmp/isaflow-slurm.XXXXXX)
ETC=$WORK/etc
export SLURM_CONF=$ETC/slurm.conf
chmod 755 "$WORK"
mkdir -p "$ETC" "$WORK/state" "$WORK/spool" "$WORK/munge" "$WORK/log"
PIDS=()   # "name:pid" of every daemon started here
STATUS=1

stop_all() {
    local entry
    if [ -n "${SNAKEMAKE_PID:-}" ]; then kill "$SNAKEMAKE_PID" 2>/dev/null || true; wait "$SNAKEMAKE_PID" 2>/dev/null || true; fi
    # jobs of this private cluster only (its own slurmctld): cancel before the daemons stop
    timeout 10 scancel --full --quiet $(timeout 5 squeue -h -o %i 2>/dev/null) 2>/dev/null || true
    sleep 1
    for ((i = ${#PIDS[@]} - 1; i >= 0; i--)); do
        entry=${PIDS[i]}
        kill "${entry#*:}" 2>/dev/null || true
        for _ in $(seq 50); do kill -0 "${entry#*:}" 2>/dev/null || break; sleep 0.2; done
        kill -9 "${entry#*:}" 2>/dev/null || true
    done
    rm -f "$WORK"/*.pid "$WORK"/munge/*.pid
    [ "$(readlink /etc/slurm/slurm.conf 2>/dev/null)" != "$SLURM_CONF" ] || rm -f /etc/slurm/slurm.conf
    if [ "${KEEP:-0}" = 1 ] || [ "$STATUS" != 0 ]; then
        log "kept $WORK (logs in $WORK/log)"
    else
        rm -rf "$WORK"
    fi
}
trap stop_all EXIT
trap 'exit 143' TERM INT HUP

started() { PIDS+=("$1:$2"); echo "$2" >"$WORK/$1.pid"; }

wait_for() {  # wait_for SECONDS WHAT COMMAND...
    local secs=$1 what=$2; shift 2
    local end=$((SECONDS + secs))
    while [ $SECONDS -lt $end ]; do timeout 5 "$@" >/dev/null 2>&1 && return 0; sleep 0.5; done
    log "timed out waiting for $what"; tail -n 20 "$WORK"/log/* >&2 || true; exit 1
}

# --- munge: the distribution's key and socket (SLURM's clients use the default
# socket whatever AuthInfo says); a munged already running is used as it is --
[ -s /etc/munge/munge.key ] || mungekey --create --keyfile=/etc/munge/munge.key
if ! munge -n 2>/dev/null | unmunge >/dev/null 2>&1; then
    install -d -o munge -g munge -m 755 /run/munge
    setpriv --reuid=munge --regid=munge --clear-groups munged -F --pid-file="$WORK/munge/munged.pid" \
        --log-file="$WORK/log/munged.log" --seed-file="$WORK/munge/seed" 2>/dev/null &
    started munged $!
    wait_for 10 munged sh -c 'munge -n | unmunge'
fi
# --- MariaDB for slurmdbd (job accounting is what sacct reads) ---------------
mariadb-install-db --user=root --datadir="$WORK/mysql" --auth-root-authentication-method=socket \
    >"$WORK/log/mariadb-install.log" 2>&1
mariadbd --no-defaults --user=root --datadir="$WORK/mysql" --socket="$WORK/mysql.sock" \
    --port=16306 --bind-address=127.0.0.1 --skip-name-resolve --log-error="$WORK/log/mariadb.log" &
started mariadbd $!
wait_for 30 MariaDB mariadb-admin --socket="$WORK/mysql.sock" ping
mariadb --socket="$WORK/mysql.sock" -e "CREATE USER 'slurm'@'127.0.0.1' IDENTIFIED BY 'isaflow';
    GRANT ALL ON slurm_acct_db.* TO 'slurm'@'127.0.0.1';"

# --- SLURM configuration ----------------------------------------------------
NODE=$(hostname -s)
NODELINE=$(slurmd -C | head -n 1)
cat >"$ETC/slurmdbd.conf" <<EOF
AuthType=auth/munge
DbdHost=localhost
DbdPort=16819
SlurmUser=root
StorageType=accounting_storage/mysql
StorageHost=127.0.0.1
StoragePort=16306
StorageUser=slurm
StoragePass=isaflow
StorageLoc=slurm_acct_db
PidFile=$WORK/slurmdbd.daemon.pid
LogFile=$WORK/log/slurmdbd.log
EOF
chmod 600 "$ETC/slurmdbd.conf"
cat >"$SLURM_CONF" <<EOF
ClusterName=isaflow
SlurmctldHost=$NODE(127.0.0.1)
SlurmctldPort=16817
SlurmdPort=16818
AuthType=auth/munge
SlurmUser=root
SlurmdUser=root
StateSaveLocation=$WORK/state
SlurmdSpoolDir=$WORK/spool
SlurmctldPidFile=$WORK/slurmctld.daemon.pid
SlurmdPidFile=$WORK/slurmd.daemon.pid
SlurmctldLogFile=$WORK/log/slurmctld.log
SlurmdLogFile=$WORK/log/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SelectType=select/cons_tres
SelectTypeParameters=CR_Core_Memory
MpiDefault=none
ReturnToService=2
SchedulerType=sched/backfill
AccountingStorageType=accounting_storage/slurmdbd
AccountingStorageHost=localhost
AccountingStoragePort=16819
AccountingStoreFlags=job_comment
JobAcctGatherType=jobacct_gather/linux
JobCompType=jobcomp/none
MinJobAge=300
$NODELINE NodeAddr=127.0.0.1 State=UNKNOWN
PartitionName=debug Nodes=$NODE Default=YES MaxTime=INFINITE State=UP
EOF

mkdir -p /etc/slurm
ln -s "$SLURM_CONF" /etc/slurm/slurm.conf

# --- daemons ------------------------------------------------------------------
slurmdbd -D >"$WORK/log/slurmdbd.out" 2>&1 &
started slurmdbd $!
wait_for 30 slurmdbd sacctmgr -n list cluster
sacctmgr -i add cluster isaflow >/dev/null 2>&1 || true
slurmctld -D -i >"$WORK/log/slurmctld.out" 2>&1 &
started slurmctld $!
wait_for 30 slurmctld scontrol ping
slurmd -D -N "$NODE" >"$WORK/log/slurmd.out" 2>&1 &
started slurmd $!
wait_for 60 "node $NODE idle" sh -c "sinfo -h -n $NODE -o %t | grep -qx idle"
log "cluster up: $(sinfo -h -o '%P %D %t %c cpus %m MB')"

# --- the workflow: local reference run, then the same through SLURM ------------
git clone -q "$ROOT" "$WORK/local"
git clone -q "$ROOT" "$WORK/slurm"
if [ $# -gt 0 ]; then
    TARGETS=("$@")
elif grep -qE '^rule paper:' "$ROOT"/Snakefile "$ROOT"/workflow/rules/*.smk 2>/dev/null; then
    TARGETS=(paper)
else
    TARGETS=(figures/fig06_single_coarse.png)
fi
[ -f "$WORK/slurm/workflow/profiles/slurm/config.yaml" ] ||
    { echo "FAIL: HEAD has no workflow/profiles/slurm (snakemake would silently run locally)"; exit 1; }
touch "$WORK/stamp"
sleep 1
log "local run of ${TARGETS[*]}"
(cd "$WORK/local" && PYTHONPATH=$WORK/local/src exec "$PY" -m snakemake -c2 \
    --workflow-profile workflow/profiles/default "${TARGETS[@]}") >"$WORK/log/local.log" 2>&1 &
SNAKEMAKE_PID=$!
wait "$SNAKEMAKE_PID" || { tail -n 30 "$WORK/log/local.log"; exit 1; }
log "SLURM run of ${TARGETS[*]}"
T0=$(date +%s)
(cd "$WORK/slurm" && PYTHONPATH=$WORK/slurm/src exec "$PY" -m snakemake --profile "$ROOT/tests/cluster/profile" \
    --workflow-profile workflow/profiles/slurm "${TARGETS[@]}") >"$WORK/log/slurm.log" 2>&1 &
SNAKEMAKE_PID=$!
wait "$SNAKEMAKE_PID" ||
    { tail -n 40 "$WORK/log/slurm.log"; cat "$WORK"/slurm/.snakemake/slurm_logs/*/*/*.log 2>/dev/null | tail -n 40; exit 1; }
SNAKEMAKE_PID=
T1=$(date +%s)
log "SLURM run took $((T1 - T0)) s"

# --- checks -------------------------------------------------------------------
SACCT=$(sacct -X -n -P -S now-1hour --format=JobID,JobName,Comment,State,ExitCode,Elapsed,NCPUS,ReqMem)
echo "sacct (JobID|JobName|Comment|State|ExitCode|Elapsed|NCPUS|ReqMem):"
echo "$SACCT"
SUBMITTED=$(grep -c "Job .* has been submitted with SLURM jobid" "$WORK/log/slurm.log" || true)
COMPLETED=$(echo "$SACCT" | grep -c '|COMPLETED|0:0|' || true)
echo "jobs submitted by snakemake: $SUBMITTED; COMPLETED in sacct: $COMPLETED; wall time: $((T1 - T0)) s"
[ "$SUBMITTED" -ge 1 ] && [ "$COMPLETED" = "$SUBMITTED" ] || { echo "FAIL: not every job completed in SLURM"; exit 1; }
"$PY" "$ROOT/tests/cluster/compare_outputs.py" "$WORK/local" "$WORK/slurm" "$WORK/stamp" ||
    { echo "FAIL: outputs differ"; exit 1; }
STATUS=0
echo "PASSED: ${TARGETS[*]} through SLURM equals the local run"
