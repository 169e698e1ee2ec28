// The declarations of a program's outputs as Markdown (what --list-outputs prints and
// docs/outputs.md holds), against text written out by hand.
#include "leglab/app/output_docs.h"

#include <gtest/gtest.h>

#include <array>
#include <string>

namespace leglab {
namespace {

constexpr std::array<ColumnDoc, 2> kColumns{{
    {"tick", "", "the tick, from 0"},
    {"angle_deg", "deg", "the angle"},
}};

TEST(OutputDocs, ColumnNamesAreTheDeclaredNamesInOrder) {
  EXPECT_EQ(ColumnNames(kColumns), (std::vector<std::string>{"tick", "angle_deg"}));
  EXPECT_TRUE(ColumnNames({}).empty());
}

TEST(OutputDocs, MarkdownHasAHeadingPerFileAndATableOfItsColumns) {
  const OutputDoc outputs[] = {{"a_<mode>.csv", "One table.", kColumns},
                               {"b.json", "Prose only.", {}}};
  EXPECT_EQ(OutputsMarkdown(outputs),
            "### `a_<mode>.csv`\n"
            "\n"
            "One table.\n"
            "\n"
            "| column | unit | description |\n"
            "|---|---|---|\n"
            "| `tick` |  | the tick, from 0 |\n"
            "| `angle_deg` | deg | the angle |\n"
            "\n"
            "### `b.json`\n"
            "\n"
            "Prose only.\n"
            "\n");
}

}  // namespace
}  // namespace leglab
