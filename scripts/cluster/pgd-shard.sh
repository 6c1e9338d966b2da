#!/usr/bin/env bash
# One shard of a vademecum build split across machines, as a Slurm array task or a Kubernetes
# Indexed Job pod runs it:
#   pgd-shard.sh N PGD-BUILD-ARGUMENTS...
# runs `pgd build PGD-BUILD-ARGUMENTS... --shard K/N`, K taken from SLURM_ARRAY_TASK_ID
# (an array counted from 1: --array=1-N) or JOB_COMPLETION_INDEX (counted from 0, so K is
# one more), or SHARD_INDEX (from 1) anywhere else. Every shard gets the same arguments; the
# parts land beside the vademecum (--out FILE.vdm gives FILE.part-K-of-N.vdp), for
# `pgd merge` to join once all are written. PGD names the binary (default: pgd on PATH).
set -euo pipefail

if [[ $# -lt 2 ]]; then
    echo "usage: $0 N PGD-BUILD-ARGUMENTS... (see docs/pgd.md, Builds split across machines)" >&2
    exit 2
fi
count=$1
shift
if [[ -n "${SLURM_ARRAY_TASK_ID:-}" ]]; then
    index=$SLURM_ARRAY_TASK_ID
elif [[ -n "${JOB_COMPLETION_INDEX:-}" ]]; then
    index=$((JOB_COMPLETION_INDEX + 1))
elif [[ -n "${SHARD_INDEX:-}" ]]; then
    index=$SHARD_INDEX
else
    echo "$0: no shard index: set SLURM_ARRAY_TASK_ID, JOB_COMPLETION_INDEX or SHARD_INDEX" >&2
    exit 2
fi
exec "${PGD:-pgd}" build "$@" --shard "$index/$count"
