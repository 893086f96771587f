#!/bin/bash
# A draglab campaign across a Slurm allocation: rank 0 holds the database (keep it on a disk
# that takes file locks, not a parallel filesystem written by many nodes), every other task runs
# units with --cpus-per-task OpenMP threads. Submit: sbatch scripts/slurm_campaign.sh [SPEC] [DB]
# A killed or timed-out job is continued by submitting it again (--resume also starts a new one).
# Units too large for one task: [lbm] ranks_per_unit = k in the spec runs each unit's box on k
# tasks together (the tasks other than rank 0 must be a multiple of k).
#SBATCH --job-name=draglab-campaign
#SBATCH --nodes=4
#SBATCH --ntasks-per-node=8
#SBATCH --cpus-per-task=4
#SBATCH --time=24:00:00
set -euo pipefail
spec="${1:-paper}"
db="${2:-$SLURM_SUBMIT_DIR/campaign.db}"
export OMP_PROC_BIND=close OMP_PLACES=cores
# --no-kill and --kill-on-bad-exit=0: a failed node or task does not end the job; rank 0 hands
# the lost units to the other ranks after --worker-timeout seconds.
srun --no-kill --kill-on-bad-exit=0 --mpi=pmix \
  draglab campaign run "$spec" --db "$db" --resume \
  --threads-per-unit "$SLURM_CPUS_PER_TASK" --worker-timeout 60
