/* app/devices.h — the devices a render runs on, for either integrator.  Internal to app/. */
#ifndef RS_APP_DEVICES_H
#define RS_APP_DEVICES_H

#include "app/options.h"
#include "core/cores.h"
#include "scheduler/fault.h"

/* Creates the devices the options name into devs[].  --integrator stream: every device of
 * --devices (auto: every usable CUDA device, else the CPU, or with --shade-on host both; under an
 * MPI launcher with several ranks on this machine, this rank's share of the CUDA devices,
 * rs_devices_auto_gpus); the
 * cores are shared out without oversubscription: each GPU fallback takes one thread when a cpu
 * device is beside it (every core when it is alone), and a cpu device without an explicit
 * thread count gets the rest.  --integrator megakernel: its one device: cpu[:N] the CPU device,
 * gpu[:INDEX] that CUDA device, auto the first CUDA device of this rank's share where there is
 * one, else the CPU.  A gpu that cannot be used runs on its CPU fallback (one warning line), or
 * with --require-gpu is an error (one line, nothing left created), as is --require-gpu with
 * --devices auto where no CUDA device can be used.  Every device goes through `fault`
 * (RS_FAULT, scheduler/fault.h).  `cores` may be NULL.  Returns the count, or -1 after printing
 * an error (nothing is left created). */
int rs_devices_create(const rs_cli_options *o, const rs_fault_spec *fault, int threads,
                      rs_cores *cores, rs_device **devs);

/* --devices auto's CUDA devices for the rank with node-local rank `local_rank` of `local_size`
 * ranks on a machine with `n_gpus` CUDA devices; writes their indices, ascending, to out[] (room
 * for n_gpus) and returns how many.  With one rank (local_size <= 1): every GPU.  With at least
 * as many GPUs as ranks: the GPUs g with g mod local_size == local_rank mod local_size (each GPU
 * to exactly one rank; 4 GPUs, 2 ranks: rank 0 gpu 0 and 2, rank 1 gpu 1 and 3).  With fewer
 * GPUs than ranks: GPU local_rank mod n_gpus alone, shared with the other ranks of that residue
 * (3 ranks, 2 GPUs: ranks 0 and 2 share gpu 0).  No GPUs, or a negative count: 0.  Pure. */
int rs_devices_auto_gpus(int local_rank, int local_size, int n_gpus, int *out);

/* This process's node-local rank and the number of ranks on its machine, from an MPI
 * launcher's environment (Open MPI's OMPI_COMM_WORLD_LOCAL_RANK/_SIZE, MPICH/Hydra's
 * MPI_LOCALRANKID/MPI_LOCALNRANKS, Slurm's SLURM_LOCALID/SLURM_NTASKS_PER_NODE, PMI's
 * PMI_LOCAL_RANK/PMI_LOCAL_SIZE, MVAPICH's MV2_COMM_WORLD_LOCAL_RANK/_SIZE).  Returns 1 with
 * both set when the launcher names both (0 <= rank < size), else 0 with 0 and 1. */
int rs_devices_local_rank(int *local_rank, int *local_size);

#endif
