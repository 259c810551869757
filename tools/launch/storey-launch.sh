#!/bin/sh
# storey-launch.sh: prepares the NUC for `storey run` and starts it (tools/launch/README.md).
#   storey-launch.sh --check [--config FILE]   checks only (systemd ExecStartPre): exit 1 on a
#                                               hard failure, warnings for what only degrades
#   storey-launch.sh --config FILE [storey run options...]   checks, then exec storey run
# Environment: STOREY_BIN (default /usr/local/bin/storey), STOREY_RMEM (default 33554432 = 32 MiB
# LiDAR receive buffer ceiling), STOREY_CPUS (CPUs reserved for storey, default "2-5").
set -u
STOREY_BIN=${STOREY_BIN:-/usr/local/bin/storey}
STOREY_RMEM=${STOREY_RMEM:-33554432}
STOREY_CPUS=${STOREY_CPUS:-2-5}
check_only=0
config=""
if [ "${1:-}" = "--check" ]; then check_only=1; shift; fi
args="$*"
while [ $# -gt 0 ]; do
  if [ "$1" = "--config" ] && [ $# -gt 1 ]; then config=$2; fi
  shift
done
warn() { echo "storey-launch: warning: $*" >&2; }
fail() { echo "storey-launch: $*" >&2; exit 1; }

# 1. Network buffers: SO_RCVBUF is capped by net.core.rmem_max; the default 208 KiB holds about
#    40 ms of Mid-360 packets. Raise the ceiling (and the default) when we may.
cur=$(cat /proc/sys/net/core/rmem_max 2>/dev/null || echo 0)
if [ "$cur" -lt "$STOREY_RMEM" ]; then
  if sysctl -q -w net.core.rmem_max="$STOREY_RMEM" net.core.rmem_default=1048576 2>/dev/null; then
    echo "storey-launch: net.core.rmem_max $cur -> $STOREY_RMEM"
  else
    warn "net.core.rmem_max is $cur (< $STOREY_RMEM) and cannot be raised here (needs root):" \
         "the LiDAR socket buffer will be capped"
  fi
fi

# 2. RT throttling: by default SCHED_FIFO threads get 950 ms per 1 s; a runaway RT task then
#    stalls instead of locking the machine. -1 (unthrottled) is what some tuning guides set:
#    say so, keep it (the watchdog task guards storey's own overruns).
rt=$(cat /proc/sys/kernel/sched_rt_runtime_us 2>/dev/null || echo "?")
[ "$rt" = "-1" ] && warn "kernel.sched_rt_runtime_us = -1: RT throttling is off"

# 3. Isolated cores: storey's task table pins to CPUs $STOREY_CPUS (config rates.*.cpu);
#    isolcpus/nohz_full keep other work and the tick off them.
cmdline=$(cat /proc/cmdline 2>/dev/null || echo "")
case "$cmdline" in *isolcpus=*) ;; *) warn "no isolcpus= on the kernel command line (see README)";; esac
case "$cmdline" in *nohz_full=*) ;; *) warn "no nohz_full= on the kernel command line";; esac

# 4. CPU frequency governor: powersave/schedutil ramp the clock and add ms of latency.
for g in /sys/devices/system/cpu/cpu*/cpufreq/scaling_governor; do
  [ -r "$g" ] || continue
  v=$(cat "$g")
  if [ "$v" != "performance" ]; then
    if ! echo performance > "$g" 2>/dev/null; then
      warn "$(dirname "$(dirname "$g")" | xargs basename) governor is '$v', not 'performance'"
    fi
  fi
done

# 5. Capabilities: SCHED_FIFO needs CAP_SYS_NICE (or LimitRTPRIO), mlockall needs CAP_IPC_LOCK
#    (or LimitMEMLOCK=infinity). storey degrades with one warning each; say it here first.
capeff=$(awk '/^CapEff/ {print $2}' /proc/self/status 2>/dev/null)
has_cap() { [ -n "$capeff" ] && [ $(( 0x$capeff >> $1 & 1 )) -eq 1 ]; }
rtprio=$(ulimit -r 2>/dev/null || echo 0)
memlock=$(ulimit -l 2>/dev/null || echo 0)
if ! has_cap 23 && [ "$rtprio" = "0" ]; then
  warn "no CAP_SYS_NICE and RLIMIT_RTPRIO 0: tasks will run without SCHED_FIFO"
fi
if ! has_cap 14 && [ "$memlock" != "unlimited" ]; then
  warn "no CAP_IPC_LOCK and RLIMIT_MEMLOCK $memlock: memory will not be locked"
fi

# 6. The configuration itself.
[ -x "$STOREY_BIN" ] || fail "$STOREY_BIN: not found or not executable (set STOREY_BIN)"
if [ -n "$config" ]; then
  "$STOREY_BIN" check-config "$config" >/dev/null || fail "$config: invalid (storey check-config $config)"
fi
[ "$check_only" = 1 ] && exit 0
[ -n "$config" ] || fail "usage: storey-launch.sh [--check] --config FILE [storey run options]"
# shellcheck disable=SC2086
exec "$STOREY_BIN" run $args
