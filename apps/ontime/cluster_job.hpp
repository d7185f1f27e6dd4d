#pragma once
// The MPI job an `ontime` process belongs to, when a launcher started it: `mpirun -np N ontime
// ...` (Open MPI) or `srun --mpi=pmix ontime ...` (SLURM). Without a launcher the process joins
// nothing and never touches MPI: no start-up cost, no message.
//
// In a job of N > 1 ranks, the commands that split work (collect, evaluate, table, study, run,
// tamp) hand job_ranks() to the library; every rank runs the same command on the same inputs,
// and rank 0 alone prints and writes the outputs (the other ranks' stdout goes to /dev/null).
// The other commands refuse to run split (exit 2), since they would only repeat the same work.
//
// Errors: every rank checks the command line and the inputs before the first exchange of
// results. A rank that fails there meets the others at that exchange (a gate every rank passes
// once) instead of leaving them waiting: the lowest failing rank prints its message (so a usage
// error that every rank finds is printed once, by rank 0), and every rank exits with its code
// (2 for bad input or usage). A rank that fails later, when the others may be waiting on it,
// prints its message and ends the whole job (MPI_Abort) with its code.

#include "ontime/util/ranks.hpp"

namespace ontime::cli {

// Joins the job when the environment shows a launcher (Open MPI's OMPI_COMM_WORLD_SIZE, PMIx's
// PMIX_RANK, PMI's PMI_RANK); throws UsageError when this ontime was built without MPI and a
// launcher asks for more than one rank, or when srun started several tasks without MPI.
void join_cluster_job(int& argc, char**& argv);

// The job's ranks, or nullptr for a process on its own.
const Ranks* job_ranks() noexcept;

// True on rank 0 or in a process on its own: the rank that prints and writes.
bool is_job_root() noexcept;

// Ends the process's part in the job after the command returned (code 0) or threw (code 1 or
// 2, `message` already formatted) and returns the exit code the process should end with: prints
// `message` where the rules above say so, meets the other ranks or ends the job, finalizes MPI.
int leave_cluster_job(int code, const char* message) noexcept;

}  // namespace ontime::cli
