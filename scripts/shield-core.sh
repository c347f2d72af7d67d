#!/bin/sh
# Shields one CPU core for a realtime run: every task that can move goes to a
# cpuset without that core, so only the plant, its controller and the core's
# own kernel threads run there (docs/guide/running.md, "A host for realtime").
#
#   sudo scripts/shield-core.sh on [CORE]    # default core: the last one
#   sudo scripts/shield-core.sh run CORE -- plant run scene.toml ...
#   sudo scripts/shield-core.sh off
#
# `on` also turns RT throttling off (kernel.sched_rt_runtime_us = -1; the old
# value is kept and `off` restores it). Needs root and the cgroup v1 cpuset
# hierarchy (/sys/fs/cgroup/cpuset) or cgroup v2 with the cpuset controller.
# Written by hand: cset(1) does this but is not installed on most machines.
set -eu

cg=/sys/fs/cgroup/cpuset
[ -d "$cg" ] || cg=/sys/fs/cgroup
state=/run/amb-shield
usage() { echo "usage: $0 on [CORE] | run CORE -- COMMAND... | off" >&2; exit 2; }
cpus_of() { cat "$1/cpuset.cpus" 2>/dev/null || cat "$1/cpuset.cpus.effective"; }

# v1 names its files cpuset.cpus / tasks; v2 cpuset.cpus / cgroup.procs.
enter() { # enter CGROUP PID
    if [ -f "$1/tasks" ]; then echo "$2" >"$1/tasks"; else echo "$2" >"$1/cgroup.procs"; fi
}

case "${1:-}" in
on)
    last=$(($(nproc --all) - 1))
    core=${2:-$last}
    [ "$core" -ge 1 ] 2>/dev/null && [ "$core" -le "$last" ] || {
        echo "shield-core: core $core: must be 1 to $last (core 0 keeps the rest of the system)" >&2
        exit 2
    }
    # A second `on` would save the first one's settings as the ones to restore.
    [ -d "$state" ] && {
        echo "shield-core: core $(cat "$state/core" 2>/dev/null) is already shielded: \`$0 off\` first" >&2
        exit 2
    }
    rest=$(seq -s, 0 "$last" | tr ',' '\n' | grep -vx "$core" | paste -sd, -)
    mask=0
    for c in $(echo "$rest" | tr ',' ' '); do mask=$((mask | (1 << c))); done
    mkdir -p "$state" "$cg/system" "$cg/shield"
    [ -f "$cg/cgroup.subtree_control" ] && echo +cpuset >"$cg/cgroup.subtree_control" 2>/dev/null || true
    echo "$rest" >"$cg/system/cpuset.cpus"
    echo "$core" >"$cg/shield/cpuset.cpus"
    for g in system shield; do
        [ -f "$cg/$g/cpuset.mems" ] && cat "$cg/cpuset.mems" >"$cg/$g/cpuset.mems" 2>/dev/null || true
    done
    moved=0
    kept=0
    for pid in $(cat "$cg/tasks" 2>/dev/null || cat "$cg/cgroup.procs"); do
        # Per-CPU kernel threads cannot move: they stay, and run rarely.
        if enter "$cg/system" "$pid" 2>/dev/null; then moved=$((moved + 1)); else kept=$((kept + 1)); fi
    done
    cat /proc/sys/kernel/sched_rt_runtime_us >"$state/rt_runtime_us"
    echo "$core" >"$state/core"
    # Unbound kernel work (writeback, block I/O completion) off the core too.
    wq=/sys/devices/virtual/workqueue/cpumask
    if [ -w "$wq" ]; then
        cat "$wq" >"$state/wq_cpumask"
        printf '%x\n' "$mask" >"$wq" || echo "shield-core: $wq: left as it was" >&2
    fi
    # Device interrupts (the disk's and the network's completions) off the core. Those the
    # kernel manages itself (a multi-queue disk's) refuse and stay: named below, since
    # every disk write on the machine then interrupts the shielded core.
    mkdir -p "$state/irq"
    irqs=0
    stay=""
    for f in /proc/irq/*/smp_affinity_list; do
        d=$(dirname "$f")
        n=$(basename "$d")
        old=$(cat "$f" 2>/dev/null) || continue
        if echo "$rest" >"$f" 2>/dev/null; then
            echo "$old" >"$state/irq/$n"
            irqs=$((irqs + 1))
        elif [ "$(cat "$d/effective_affinity_list" 2>/dev/null)" = "$core" ]; then
            stay="$stay $n ($(grep -E "^ *$n:" /proc/interrupts | awk '{print $NF}'))"
        fi
    done
    [ -z "$stay" ] || echo "shield-core: interrupts that cannot leave core $core:$stay" >&2
    if [ -w /proc/irq/default_smp_affinity ]; then
        cat /proc/irq/default_smp_affinity >"$state/irq_default"
        printf '%x\n' "$mask" >/proc/irq/default_smp_affinity 2>/dev/null || true
    fi
    echo -1 >/proc/sys/kernel/sched_rt_runtime_us
    echo "shield-core: core $core shielded ($moved tasks moved to cores $rest, $kept kernel threads stay," \
        "$irqs interrupts moved);" "kernel.sched_rt_runtime_us = -1 (was $(cat "$state/rt_runtime_us"))"
    ;;
run)
    [ $# -ge 4 ] && [ "$3" = "--" ] || usage
    core=$2
    shift 3
    [ -d "$cg/shield" ] || { echo "shield-core: no shield: run \`$0 on $core\` first" >&2; exit 2; }
    [ "$(cpus_of "$cg/shield")" = "$core" ] || {
        echo "shield-core: the shield is core $(cpus_of "$cg/shield"), not $core" >&2
        exit 2
    }
    # The command runs in a cpuset with every core, so that it can pin itself
    # to the shielded one (controller.pin_cores) and leave the rest elsewhere.
    mkdir -p "$cg/launch"
    cat "$cg/cpuset.cpus" >"$cg/launch/cpuset.cpus"
    [ -f "$cg/launch/cpuset.mems" ] && cat "$cg/cpuset.mems" >"$cg/launch/cpuset.mems" 2>/dev/null || true
    enter "$cg/launch" $$
    exec "$@"
    ;;
off)
    for g in launch shield system; do
        [ -d "$cg/$g" ] || continue
        for pid in $(cat "$cg/$g/tasks" 2>/dev/null || cat "$cg/$g/cgroup.procs"); do
            enter "$cg" "$pid" 2>/dev/null || true
        done
        rmdir "$cg/$g" 2>/dev/null || echo "shield-core: $cg/$g still has tasks; left in place" >&2
    done
    if [ -f "$state/wq_cpumask" ]; then
        cat "$state/wq_cpumask" >/sys/devices/virtual/workqueue/cpumask || true
    fi
    for f in "$state"/irq/*; do
        [ -f "$f" ] && cat "$f" >"/proc/irq/$(basename "$f")/smp_affinity_list" 2>/dev/null || true
    done
    [ -f "$state/irq_default" ] && cat "$state/irq_default" >/proc/irq/default_smp_affinity 2>/dev/null || true
    if [ -f "$state/rt_runtime_us" ]; then
        cat "$state/rt_runtime_us" >/proc/sys/kernel/sched_rt_runtime_us
        echo "shield-core: off; kernel.sched_rt_runtime_us = $(cat "$state/rt_runtime_us")"
        rm -rf "$state"
    else
        echo "shield-core: off"
    fi
    ;;
*) usage ;;
esac
