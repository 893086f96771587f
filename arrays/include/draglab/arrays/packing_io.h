// draglab/arrays/packing_io.h: packings in HDF5 (docs/packing_format.md).
//
// Layout: group /packing with datasets centers [N,3] and radii [N] (lengths in d_ref, the same
// units as box_length), box_length [3], and attributes phi, n, seed, generator, settings (JSON),
// length_unit, draglab_version and, when given, the statistics (min_gap, q6, g_contact,
// crystalline_fraction, mean_neighbours). Opens in h5dump and h5py.
#pragma once

#include <string>

#include "draglab/arrays/packing.h"

namespace draglab {
namespace arrays {

/// Writes atomically (a temporary file renamed into place): on any error nothing is left at
/// `path`. Throws draglab::Error(kInvalidArgument) for an unwritable path.
void write_packing_hdf5(const std::string& path, const Packing& packing,
                        const PackingStatistics* statistics = nullptr);

/// Reads a packing written by write_packing_hdf5 (or any file with the same layout). Throws
/// draglab::Error(kInvalidArgument) naming the path and the missing/malformed item, also for
/// datasets of more values than 10^7 spheres have (checked before any allocation) and for
/// attributes (generator, settings, seed) that hold more than one value. The file is read first
/// in a child process (core/isolated.h): a damaged file that crashes, hangs or exhausts memory in
/// libhdf5 is reported as damaged (kInvalidArgument) instead of ending the caller.
Packing read_packing_hdf5(const std::string& path);

/// The same read in this process only, without that protection: for the fuzzer (which must see
/// such crashes) and for callers that isolate the read themselves.
Packing read_packing_hdf5_in_process(const std::string& path);

}  // namespace arrays
}  // namespace draglab
