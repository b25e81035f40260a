// Progress lines (issue 14 item 6): on a terminal one line in place that fits 80 columns with the
// elapsed time and an ETA; in a log (stderr redirected) a plain line every ~10 s; none with -q.
#include "helpers.hpp"
#include "io/progress.hpp"

#include <cstdlib>
#include <filesystem>
#include <sstream>

namespace fs = std::filesystem;
using namespace rocklab;

TEST(Progress, LinesFitEightyColumnsAndLeadWithTheTimes) {
  EXPECT_EQ(ProgressLine::duration(7.4), "7s");
  EXPECT_EQ(ProgressLine::duration(83), "1m23s");
  EXPECT_EQ(ProgressLine::duration(7500), "2h05m");
  EXPECT_EQ(ProgressLine::duration(-3), "0s");
  const ProgressLine line("test", false, 1);
  const std::string state(200, 'x'); // a state far wider than a terminal
  const std::string shown = line.format(state, 83, 45, 79);
  EXPECT_EQ(shown.size(), 79u);
  EXPECT_EQ(shown.rfind("[rocklab test] 1m23s, ETA 45s  xxx", 0), 0u) << shown;
  EXPECT_EQ(line.format("loading", 5, -1, 79), "[rocklab test] 5s  loading"); // no ETA known
  EXPECT_EQ(line.format(state, 5, -1, 0).size(), 19u + 200u);                 // a log line: whole
  EXPECT_FALSE(line.due());                                                   // disabled: never due
}

TEST(Progress, ARedirectedRunLogsPlainLinesAndQuietLogsNone) {
  // demo.json runs a few seconds; with a 0.5 s log interval its log holds several lines, each
  // a whole line (no carriage returns) naming the stage, the percentage and (later) an ETA.
  const fs::path dir = test::scratch_root() / "progress";
  fs::create_directories(dir);
  const std::string scene = test::source_dir() + "/examples/demo.json";
  std::string log;
  ASSERT_EQ(test::run_command("ROCKLAB_PROGRESS_SECONDS=0.5 " + test::binary() + " run " + scene +
                                  " -o " + (dir / "a").string() + " --threads 1",
                              &log),
            0)
      << log;
  std::istringstream in(log);
  int lines = 0, with_eta = 0;
  for (std::string l; std::getline(in, l);)
    if (l.rfind("[rocklab run] ", 0) == 0) {
      ++lines;
      with_eta += l.find(", ETA ") != std::string::npos;
      EXPECT_NE(l.find("stage 1/1"), std::string::npos) << l;
      EXPECT_EQ(l.find('\r'), std::string::npos) << l;
    }
  EXPECT_GE(lines, 3) << log;
  EXPECT_GE(with_eta, 1) << log;
  ASSERT_EQ(test::run_command("ROCKLAB_PROGRESS_SECONDS=0.5 " + test::binary() + " run " + scene +
                                  " -o " + (dir / "b").string() + " --threads 1 -q",
                              &log),
            0)
      << log;
  EXPECT_EQ(log.find("[rocklab run]"), std::string::npos) << log;
}
