#include "lab/calibration/ranks.hpp"

#include <chrono>
#include <cstdlib>
#include <stdexcept>
#include <thread>
#include <vector>

#ifdef ROCKLAB_HAVE_MPI
#define OMPI_SKIP_MPICXX 1 // the C API only (the deprecated C++ bindings warn)
#define MPICH_SKIP_MPICXX 1
#include <mpi.h>
#endif

namespace rocklab::calibration {

#ifdef ROCKLAB_HAVE_MPI

namespace {

// Open MPI, MPICH/Hydra and Slurm's PMI each leave one of these in a launched process.
bool launched_by_mpi() {
  for (const char* v : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMIX_RANK"})
    if (std::getenv(v))
      return true;
  return false;
}

// Waits for a non-blocking collective by polling with short sleeps: a rank waiting for another
// rank's tests must not busy-poll a core those tests need (blocking collectives spin).
void finish(MPI_Request& req) {
  int done = 0;
  for (MPI_Test(&req, &done, MPI_STATUS_IGNORE); !done; MPI_Test(&req, &done, MPI_STATUS_IGNORE))
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
}

} // namespace

Ranks::Ranks() {
  if (!launched_by_mpi())
    return;
  int provided = 0;
  MPI_Init_thread(nullptr, nullptr, MPI_THREAD_FUNNELED, &provided);
  started_ = true;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
  MPI_Comm_size(MPI_COMM_WORLD, &size_);
}

Ranks::~Ranks() {
  if (started_)
    MPI_Finalize();
}

bool Ranks::all(bool ok) const {
  if (size_ == 1)
    return ok;
  int in = ok ? 1 : 0, out = 0;
  MPI_Request req;
  MPI_Iallreduce(&in, &out, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD, &req);
  finish(req);
  return out == 1;
}

double Ranks::sum(double v) const {
  if (size_ == 1)
    return v;
  double out = 0;
  MPI_Request req;
  MPI_Iallreduce(&v, &out, 1, MPI_DOUBLE, MPI_SUM, MPI_COMM_WORLD, &req);
  finish(req);
  return out;
}

std::string Ranks::broadcast(const std::string& text) const {
  if (size_ == 1)
    return text;
  unsigned long long n = text.size();
  MPI_Request req;
  MPI_Ibcast(&n, 1, MPI_UNSIGNED_LONG_LONG, 0, MPI_COMM_WORLD, &req);
  finish(req);
  std::vector<char> buf(text.begin(), text.end());
  buf.resize(n);
  MPI_Ibcast(buf.data(), static_cast<int>(n), MPI_CHAR, 0, MPI_COMM_WORLD, &req);
  finish(req);
  return std::string(buf.begin(), buf.end());
}

bool Ranks::available() {
  return true;
}

#else

Ranks::Ranks() {
  // Several copies of one campaign writing one OUTDIR would spoil it: refuse instead.
  for (const char* v : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE"})
    if (const char* n = std::getenv(v); n && std::atoi(n) > 1)
      throw std::runtime_error(std::string("started by an MPI launcher with ") + n +
                               " ranks, but this rocklab was built without MPI (install "
                               "libopenmpi-dev and build again, or use --jobs N)");
}
Ranks::~Ranks() = default;
bool Ranks::all(bool ok) const {
  return ok;
}
double Ranks::sum(double v) const {
  return v;
}
std::string Ranks::broadcast(const std::string& text) const {
  return text;
}
bool Ranks::available() {
  return false;
}

#endif

} // namespace rocklab::calibration
