// The command-line tool as a user meets it: exit codes, messages and the JSON report.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <string>

#include "cli/run_cli.h"

using topopt::testing::run_cli;

namespace {

std::string ex(const std::string& name) { return std::string(TOPOPT_SHARED_DATA) + "/examples/" + name; }

}  // namespace

TEST(CliInfo, HelpAndUsage) {
  EXPECT_EQ(run_cli("--help").code, 0);
  auto r = run_cli("info --help");
  EXPECT_EQ(r.code, 0);
  EXPECT_NE(r.out.find("--non-design"), std::string::npos);
  EXPECT_EQ(run_cli("frobnicate").code, 2);
  EXPECT_EQ(run_cli("info --part").code, 2);
  EXPECT_EQ(run_cli("info --part x.step --bogus").code, 2);
}

TEST(CliInfo, NumbersMustBeFinite) {
  const std::string part = " --part " + ex("rocker.step");
  for (const char* bad : {"nan", "inf", "-inf", "1e999"}) {
    auto r = run_cli("info --tolerance " + std::string(bad) + part);
    EXPECT_EQ(r.code, 2) << bad;
    EXPECT_NE(r.out.find("--tolerance takes a finite number, not '" + std::string(bad) + "'"), std::string::npos)
        << r.out;
  }
  auto r = run_cli("info --time-budget -5" + part);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.out.find("--time-budget takes the seconds allowed"), std::string::npos) << r.out;
  r = run_cli("mesh --size nan --out x.msh" + part);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.out.find("--size takes a finite number, not 'nan'"), std::string::npos) << r.out;
  // a budget too short for the read is a Timeout naming the file, with the advice
  r = run_cli("info --time-budget 0.001" + part);
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.out.find("error (Timeout): the part's file '" + ex("rocker.step") +
                       "' is damaged or very large: OCCT did not finish reading it within 0.001 s"),
            std::string::npos)
      << r.out;
}

TEST(CliInfo, MissingFileIsAClearError) {
  auto r = run_cli("info --part /nonexistent/part.step");
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.out.find("file not found"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("/nonexistent/part.step"), std::string::npos) << r.out;
}

TEST(CliInfo, NonDesignSolidSticksOut) {
  // The cantilever's own part used as non-design inside the (smaller) support slab: outside.
  auto r = run_cli("info --part " + ex("cantilever_nondesign.step") + " --non-design " + ex("cantilever.step"));
  EXPECT_EQ(r.code, 1);
  // The part is a compound of two solids here: the message says the part must be one solid.
  EXPECT_NE(r.out.find("exactly one solid"), std::string::npos) << r.out;
  auto r2 = run_cli("info --part " + ex("rocker.step") + " --non-design " + ex("cantilever_nondesign.step"));
  EXPECT_EQ(r2.code, 1);
  EXPECT_NE(r2.out.find("not inside the part"), std::string::npos) << r2.out;
}

TEST(CliInfo, RockerJson) {
  auto r = run_cli("info --json --part " + ex("rocker.step") + " --non-design " + ex("rocker_nondesign.step"));
  ASSERT_EQ(r.code, 0) << r.out;
  nlohmann::json j = nlohmann::json::parse(r.out);
  ASSERT_EQ(j["nondesign"]["solids"].size(), 3u);
  for (const auto& solid : j["nondesign"]["solids"]) {
    int on_plane = 0, on_cylinder = 0, interior = 0;
    for (const auto& f : solid["faces"]) {
      if (f["on"] == "interior") {
        EXPECT_EQ(f["surface"], "Cylinder");
        ++interior;
        continue;
      }
      std::string target = f["on_entity"];
      int index = std::stoi(target.substr(4)) - 1;
      std::string target_surface = j["part"]["faces_detail"][index]["surface"];
      EXPECT_EQ(target_surface, f["surface"]);
      (f["surface"] == "Plane" ? on_plane : on_cylinder)++;
    }
    EXPECT_EQ(on_plane, 2);     // top and bottom on the part's top and bottom
    EXPECT_GE(on_cylinder, 1);  // the bore on the part's bore
    EXPECT_GE(interior, 1);     // the outer cylinder inside the part
  }
  EXPECT_TRUE(j["contacts"].empty());
}

TEST(CliInfo, BracketPadsInContact) {
  auto r = run_cli("info --json --part " + ex("bracket.step") + " --non-design " + ex("bracket_nondesign.step"));
  ASSERT_EQ(r.code, 0) << r.out;
  nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["nondesign"]["solids"].size(), 7u);
  ASSERT_EQ(j["contacts"].size(), 1u);
  EXPECT_EQ(j["contacts"][0]["solids"], nlohmann::json::array({6, 7}));
}
