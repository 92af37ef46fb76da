// Measuring a kept particle file again (engine/particle_file.hpp, `crevasse measure`): the
// reloaded snapshot gives exactly the measurement of the snapshot that was written, under either
// spacing rule; so a case re-measured with its own settings reproduces its stored result.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>

#include "analysis/crevasse_measure.hpp"
#include "analysis/measurement_io.hpp"
#include "engine/particle_file.hpp"
#include "synthetic_slab.hpp"

namespace crevasse::analysis {
namespace {

TEST(MeasureAgain, AReloadedSnapshotMeasuresExactlyAsTheOriginal) {
  test::SlabSpec spec;
  spec.noise_over_spacing = 0.2;  // positions off the lattice: every bit of x and z matters
  const std::vector<test::Notch> notches = {{400.0, 40.0, 10.0}, {430.0, 60.0, 5.0}, {700.0, 35.0, 10.0},
                                            {1100.0, 80.0, 15.0}, {1500.0, 20.0, 5.0}};
  const ParticleSnapshot s = test::make_slab(spec, notches);
  const auto path = std::filesystem::temp_directory_path() /
                    ("crevasse_measure_again_" + std::to_string(::getpid()) + ".bin");
  write_particle_file(path, s);
  const ParticleSnapshot r = read_particle_file(path).snapshot;
  std::filesystem::remove(path);
  for (const char* rule : {"merge", "drop"}) {
    MeasureSettings settings;
    settings.spacing_rule = rule;
    const CrevasseMeasurement a = measure_crevasses(s, settings), b = measure_crevasses(r, settings);
    ASSERT_GE(a.crevasses.size(), 3u) << rule;  // the test measures something
    EXPECT_EQ(measurement_summary_json(a), measurement_summary_json(b)) << rule;
  }
}

}  // namespace
}  // namespace crevasse::analysis
