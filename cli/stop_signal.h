// cli/stop_signal.h: while a command that keeps checkpoints runs, SIGTERM and SIGINT ask its LBM
// runs to stop at their next check and save their checkpoints (lbm::request_stop) instead of
// ending the process at once: a batch system's stop, or the end of a working session, then loses
// no stepping. The handlers are one-shot: a second signal ends the process as before.
#pragma once

#include <signal.h>

#include "draglab/lbm/lbm.h"

namespace draglab {
namespace cli {

class StopOnSignal {
 public:
  StopOnSignal() {
    install(SIGTERM, &previous_term_);
    install(SIGINT, &previous_int_);
  }
  ~StopOnSignal() {
    sigaction(SIGTERM, &previous_term_, nullptr);
    sigaction(SIGINT, &previous_int_, nullptr);
  }
  StopOnSignal(const StopOnSignal&) = delete;
  StopOnSignal& operator=(const StopOnSignal&) = delete;

 private:
  static void handle(int) { lbm::request_stop(); }
  static void install(int signal_number, struct sigaction* previous) {
    struct sigaction action {};
    action.sa_handler = &StopOnSignal::handle;
    sigemptyset(&action.sa_mask);
    action.sa_flags = SA_RESETHAND;  // the second signal takes the default action
    sigaction(signal_number, &action, previous);
  }
  struct sigaction previous_term_ {};
  struct sigaction previous_int_ {};
};

}  // namespace cli
}  // namespace draglab
