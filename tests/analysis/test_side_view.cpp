// The side-view PNG: written, of the size that equal x/z scaling implies, legible for 2D and 3D.
#include <cairo.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <stdexcept>
#include <string>

#include "analysis/crevasse_measure.hpp"
#include "analysis/side_view.hpp"
#include "synthetic_slab.hpp"

namespace crevasse::analysis {
namespace {

using test::make_slab;
using test::Notch;
using test::SlabSpec;

struct PngSize {
  int width = 0, height = 0;
};

PngSize read_png_size(const std::filesystem::path& path) {
  cairo_surface_t* s = cairo_image_surface_create_from_png(path.c_str());
  PngSize size;
  if (cairo_surface_status(s) == CAIRO_STATUS_SUCCESS) {
    size = {cairo_image_surface_get_width(s), cairo_image_surface_get_height(s)};
  }
  cairo_surface_destroy(s);
  return size;
}

// Ice draped over a 60 m ramp, with crevasses of several depths downstream.
ParticleSnapshot draped_slab(int dim) {
  SlabSpec spec{.dim = dim, .x_max_m = 2000.0, .width_m = 20.0, .noise_over_spacing = 0.15};
  spec.base_z = [](double x) {
    return x < 500.0 ? 60.0 : (x < 700.0 ? 60.0 - 0.3 * (x - 500.0) : 0.0);
  };
  std::vector<Notch> notches;
  int k = 0;
  for (double x = 760.0; x < 1900.0; x += 70.0, ++k)
    notches.push_back({.x_m = x, .depth_m = 25.0 + 10.0 * (k % 4)});
  auto s = make_slab(spec, notches);
  s.step_top_x_m = 500.0;
  s.step_foot_x_m = 700.0;
  return s;
}

class SideViewTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() /
           ("crevasse_side_view_" +
            std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  std::filesystem::path dir_;
};

TEST_F(SideViewTest, WritesPngOfTheRequestedWidthAtTrueScale) {
  const ParticleSnapshot s = draped_slab(2);
  const CrevasseMeasurement m = measure_crevasses(s);
  SideViewOptions o;
  o.title_extra = "Pi = 0.05";
  const auto path = dir_ / "side.png";
  const SideViewImageSize size = write_side_view_png(s, path, o, &m);
  ASSERT_TRUE(std::filesystem::exists(path));
  const PngSize png = read_png_size(path);
  EXPECT_EQ(png.width, 1600);
  EXPECT_EQ(png.height, size.height_px);
  // Equal scales: the plot is (x-range) wide and (z-range) tall in the same px/m. The x-range is
  // the ice ± 0.25·H_i over 1510 px; the z-range runs from the bed (z = 0) − 0.15·H_i to the top
  // particle + 0.15·H_i + 28 px; title and axis margins add 86 px. Rounding: ±1 px.
  const double x_lo = *std::min_element(s.x.begin(), s.x.end());
  const double x_hi = *std::max_element(s.x.begin(), s.x.end());
  const double z_hi = *std::max_element(s.z.begin(), s.z.end());
  const double scale = 1510.0 / (x_hi - x_lo + 50.0);
  const double expected = std::ceil((z_hi + 30.0) * scale + 28.0 + 86.0);
  EXPECT_NEAR(size.height_px, expected, 1.0);
}

TEST_F(SideViewTest, CroppedViewIsTallerAtTheSameWidth) {
  const ParticleSnapshot s = draped_slab(2);
  SideViewOptions whole, crop;
  crop.x_min_m = 900.0;
  crop.x_max_m = 1400.0;
  crop.width_px = 1200;
  const auto a = write_side_view_png(s, dir_ / "whole.png", whole);
  const auto b = write_side_view_png(s, dir_ / "crop.png", crop);
  EXPECT_EQ(read_png_size(dir_ / "crop.png").width, 1200);
  EXPECT_GT(b.height_px, a.height_px);
}

TEST_F(SideViewTest, DamagedParticlesAreDrawnDark) {
  // One full-depth damaged column in an otherwise intact slab; no marks, no title. The pixel at
  // the column is much darker than the intact ice beside it.
  SlabSpec spec{.x_max_m = 400.0};
  const ParticleSnapshot s = make_slab(spec, {{.x_m = 200.0, .depth_m = 100.0, .width_m = 10.0}});
  SideViewOptions o;
  o.show_title = false;
  o.width_px = 800;
  o.x_min_m = 0.0;
  o.x_max_m = 400.0;
  const auto path = dir_ / "dark.png";
  write_side_view_png(s, path, o);
  cairo_surface_t* img = cairo_image_surface_create_from_png(path.c_str());
  ASSERT_EQ(cairo_surface_status(img), CAIRO_STATUS_SUCCESS);
  const int stride = cairo_image_surface_get_stride(img) / 4;
  const auto* px = reinterpret_cast<const std::uint32_t*>(cairo_image_surface_get_data(img));
  const double scale = (800.0 - 90.0) / 400.0;
  const int row =
      static_cast<int>(12.0 + (100.0 + 15.0 + 28.0 / scale - 50.0) * scale);  // z = 50 m
  auto brightness = [&](double x_m) {
    const std::uint32_t p = px[row * stride + static_cast<int>(70.0 + x_m * scale)];
    return ((p >> 16) & 0xff) + ((p >> 8) & 0xff) + (p & 0xff);
  };
  EXPECT_LT(brightness(202.5), 150u);  // near-black damaged column
  EXPECT_GT(brightness(100.0), 600u);  // light-blue intact ice
  cairo_surface_destroy(img);
}

TEST_F(SideViewTest, ThreeDimensionalSnapshotRenders) {
  const ParticleSnapshot s = draped_slab(3);
  const CrevasseMeasurement m = measure_crevasses(s);
  EXPECT_FALSE(m.crevasses.empty());
  SideViewOptions band;
  band.y_band_width_m = 10.0;
  EXPECT_EQ(write_side_view_png(s, dir_ / "all.png", {}, &m).width_px, 1600);
  EXPECT_EQ(write_side_view_png(s, dir_ / "band.png", band, &m).width_px, 1600);
  EXPECT_EQ(read_png_size(dir_ / "band.png").width, 1600);
}

TEST_F(SideViewTest, BadInputsThrowActionableErrors) {
  EXPECT_THROW(write_side_view_png(ParticleSnapshot{}, dir_ / "x.png"), std::invalid_argument);
  SideViewOptions inverted;
  inverted.x_min_m = 500.0;
  inverted.x_max_m = 100.0;
  EXPECT_THROW(write_side_view_png(draped_slab(2), dir_ / "x.png", inverted),
               std::invalid_argument);
  EXPECT_THROW(write_side_view_png(draped_slab(2), "/nonexistent-dir/x.png"), std::runtime_error);
}

}  // namespace
}  // namespace crevasse::analysis
