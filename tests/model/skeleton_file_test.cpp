#include "ontime/model/skeleton_file.hpp"

#include <gtest/gtest.h>

#include "ontime/util/error.hpp"
#include "support/paper.hpp"

namespace ontime {
namespace {

TEST(SkeletonFile, ReadsTheSkeletonsMemberAndIgnoresTheRest) {
  const SkeletonList list = parse_skeleton_file(
      R"json({"rooms": {"R1": 1}, "skeletons": [["move(R1,R2)", "move(R2,R3)"], ["move(R1,R2)", "move(R2,R4)"], ["x"]]})json",
      "world.json");
  EXPECT_EQ(list.source, "world.json");
  ASSERT_EQ(list.skeletons.size(), 3u);
  EXPECT_EQ(list.skeletons[1], (std::vector<std::string>{"move(R1,R2)", "move(R2,R4)"}));
  EXPECT_EQ(list.skeletons[2], (std::vector<std::string>{"x"}));
}

TEST(SkeletonFile, AnInstanceFileServesAsASkeletonFile) {
  const SkeletonList list = load_skeleton_file(testing::source_path("data/instances/paper/figure1.json"));
  const Problem problem = testing::paper_instance("figure1");
  ASSERT_EQ(static_cast<int>(list.skeletons.size()), problem.skeleton_count());
  for (int k = 0; k < problem.skeleton_count(); ++k) {
    for (int l = 0; l < problem.skeleton_length(k); ++l) {
      EXPECT_EQ(list.skeletons[static_cast<std::size_t>(k)][static_cast<std::size_t>(l)],
                problem.action(problem.action_at(k, l)).id);
    }
  }
}

TEST(SkeletonFile, BreakingARuleNamesThePlace) {
  const struct {
    const char* text;
    const char* place;
    const char* rule;
  } cases[] = {
      {"[1]", "top level", "must be a JSON object"},
      {R"({"skeleton": []})", "top level", "missing required key 'skeletons'"},
      {R"({"skeletons": []})", "skeletons", "at least one skeleton"},
      {R"({"skeletons": [["a"], []]})", "skeletons[1]", "at least one action"},
      {R"({"skeletons": [["a", 3]]})", "skeletons[0][1]", "must be a string"},
      {R"({"skeletons": [["a", ""]]})", "skeletons[0][1]", "non-empty"},
      {R"({"skeletons": [["a", "b", "a"]]})", "skeletons[0][2]", "appears twice"},
      {R"({"skeletons": [["a", "b"], ["c", "b"]]})", "skeletons[1][1]", "the actions before it differ"},
      {R"({"skeletons": [["a", "b"], ["b"]]})", "skeletons[1][0]", "at another position"},
      {R"({"skeletons": [["a"], ["a"]]})", "skeletons[1]", "the same skeleton as skeletons[0]"},
      {R"({"skeletons": [["a"]], "skeletons": [["b"]]})", "skeletons", "duplicate key"},
  };
  for (const auto& bad : cases) {
    try {
      parse_skeleton_file(bad.text, "file.json");
      ADD_FAILURE() << bad.text << " was accepted";
    } catch (const InputError& error) {
      EXPECT_EQ(error.place(), bad.place) << bad.text;
      EXPECT_NE(error.rule().find(bad.rule), std::string::npos) << bad.text << ": " << error.what();
    }
  }
}

}  // namespace
}  // namespace ontime
