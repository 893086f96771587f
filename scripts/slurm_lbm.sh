#!/bin/bash
# One large LBM box decomposed across a Slurm allocation: slabs of z-planes, one task per node
# with its cores as OpenMP threads (the ranks agree on every decision; rank 0 prints the drag
# with its error estimate and writes the fields). Submit:
#   sbatch scripts/slurm_lbm.sh PACKING.h5 D RE [FIELDS.h5]
# A box of nz planes takes at most nz/2 ranks. docs/scaling.md has the measured and predicted
# efficiencies.
#SBATCH --job-name=draglab-lbm
#SBATCH --nodes=8
#SBATCH --ntasks-per-node=1
#SBATCH --cpus-per-task=32
#SBATCH --time=12:00:00
set -euo pipefail
packing="$1"
d="$2"
re="$3"
fields="${4:-}"
export OMP_PROC_BIND=close OMP_PLACES=cores
srun --mpi=pmix draglab --json lbm run --packing "$packing" --d "$d" --re "$re" \
  --threads "$SLURM_CPUS_PER_TASK" ${fields:+--fields "$fields"} >"lbm_${SLURM_JOB_ID}.json"
