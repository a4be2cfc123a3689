// JSON views for summary.json.
#include <gtest/gtest.h>

#include <cmath>

#include "oobleck/analysis/summary_json.hpp"

using namespace oobleck::analysis;

TEST(AnalysisJson, FrontSpeedsCarryIssueKeysAndNullForNaN) {
  LinearFit l, t;
  l.slope = 0.6;
  l.points = 10;
  t.slope = 0.0;
  const nlohmann::json j = to_json(front_factors(l, t, 0.2));
  EXPECT_DOUBLE_EQ(j.at("v_fl").get<double>(), 0.6);
  EXPECT_DOUBLE_EQ(j.at("k_l").get<double>(), 2.0);
  EXPECT_TRUE(j.at("k_l_over_k_t").is_null());
  EXPECT_EQ(j.at("longitudinal_fit").at("points").get<int>(), 10);
}

TEST(AnalysisJson, WheelSummaryKeys) {
  HubTrack h{{0.0, 1.0, 2.0}, {1.9, 0.4, 1.1}, {0.65, 0.6, 0.58}};
  const WheelCriteria c;
  const nlohmann::json j = to_json(summarize_wheel(h, c), c);
  EXPECT_NEAR(j.at("distance").get<double>(), 1.2, 1e-12);
  EXPECT_DOUBLE_EQ(j.at("bed_surface").get<double>(), 0.5);
  EXPECT_TRUE(j.at("runs_on_surface").get<bool>());  // lowest 0.58 m >= 0.65 - 0.15/2
  EXPECT_NEAR(j.at("runs_on_surface_lowest_hub").get<double>(), 0.575, 1e-15);
  EXPECT_FALSE(j.at("sinks").get<bool>());
  EXPECT_TRUE(to_json(FlowStop{}).at("time").is_null());
}
