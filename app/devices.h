/* app/devices.h — the devices a render runs on, for either integrator.  Internal to app/. */
#ifndef RS_APP_DEVICES_H
#define RS_APP_DEVICES_H

#include "app/options.h"
#include "core/cores.h"
#include "scheduler/fault.h"

/* Creates the devices the options name into devs[].  --integrator stream: every device of
 * --devices (auto: the CPU and every CUDA device); the cores are shared out without
 * oversubscription: each GPU fallback takes one thread when a cpu device is beside it (every
 * core when it is alone), and a cpu device without an explicit thread count gets the rest.
 * --integrator megakernel: its one device: cpu[:N] the CPU device, gpu[:INDEX] that CUDA
 * device, auto CUDA device 0 where there is one, else the CPU.  A gpu that cannot be used runs
 * on its CPU fallback (one warning line).  Every device goes through `fault` (RS_FAULT,
 * scheduler/fault.h).  `cores` may be NULL.  Returns the count, or -1 after printing an error
 * (nothing is left created). */
int rs_devices_create(const rs_cli_options *o, const rs_fault_spec *fault, int threads,
                      rs_cores *cores, rs_device **devs);

#endif
