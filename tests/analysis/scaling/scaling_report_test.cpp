// The report section of the scales: blocks for the report's renderers, the plot and the
// CSV; nothing undefined prints as NaN or inf.
#include "analysis/scaling/scaling_report.h"

#include <gtest/gtest.h>

#include <map>
#include <sstream>

#include "scaling_test_data.h"

namespace lucent::analysis {
namespace {

std::string all_text(const ScalingSection& s) {
    std::string text;
    for (const Block& b : s.blocks) {
        text += b.text + "\n" + b.svg;
        for (const auto& h : b.table.header) text += h + "|";
        for (const auto& r : b.table.rows)
            for (const auto& c : r) text += c + "|";
        for (const auto& i : b.images) text += i.caption + "|";
    }
    for (const auto& [name, content] : s.files) text += name + "\n" + content;
    return text;
}

TEST(ScalingReport, SectionForPairsAndMlds) {
    const ChoiceTable mlds_table =
        read_choice_csv(testing::scaling_data_path("mlds_quadruple.csv"));
    MldsOptions options;
    options.bootstrap = 20;
    const auto mlds = fit_mlds_blocks(mlds_table, options);
    std::istringstream csv(
        "participant,task,block,question,shown_1,shown_2,value_1,value_2,choice\n"
        "P1,pair,pc,q,a,b,1,2,1\nP1,pair,pc,q,b,c,2,3,1\nP1,pair,pc,q,a,c,1,3,2\n"
        "P1,pair,pc,q,b,a,2,1,1\n"
        "P2,pair,pc,q,a,b,1,2,2\nP2,pair,pc,q,b,c,2,3,2\nP2,pair,pc,q,c,a,3,1,1\n");
    const auto paired = fit_paired_blocks(read_choice_csv(csv, "p.csv"));
    const ScalingSection s = scaling_section(
        paired, mlds, {{"s1", "/pictures/s1.png"}, {"b", "/pictures/b.png"}});
    ASSERT_FALSE(s.blocks.empty());
    EXPECT_EQ(s.blocks[0].text, "Perceptual scales");
    int plots = 0, images = 0;
    for (const Block& b : s.blocks) {
        if (b.kind == Block::kPlot) {
            ++plots;
            EXPECT_EQ(b.svg.rfind("<svg", 0), 0u);
        }
        if (b.kind == Block::kImages) {
            ++images;
            ASSERT_EQ(b.images.size(), 1u);
        }
    }
    EXPECT_EQ(plots, 2);
    EXPECT_EQ(images, 2);
    const std::string text = all_text(s);
    EXPECT_NE(text.find("s1 (0)"), std::string::npos);
    EXPECT_NE(text.find("pc: q (paired comparisons)"), std::string::npos);
    EXPECT_NE(text.find("quadruple: differs_more (difference scaling, MLDS)"),
              std::string::npos);
    EXPECT_NE(text.find("P2: "), std::string::npos);  // P2's notes (a perfect order)
    EXPECT_EQ(text.find("nan"), std::string::npos);
    EXPECT_EQ(text.find("inf"), std::string::npos);
    ASSERT_EQ(s.files.back().first, "scaling.csv");
    // One row per (block, method, participant, stimulus): each scale once, both of a
    // pair block's (Bradley-Terry and Thurstone), 3 stimuli x (2 pooled + 2
    // participants).
    std::istringstream rows(s.files.back().second);
    std::map<std::string, int> seen;
    int pair_rows = 0;
    std::string line;
    std::getline(rows, line);  // header
    while (std::getline(rows, line)) {
        std::istringstream cells(line);
        std::string block, question, method, who, stimulus;
        std::getline(cells, block, ',');
        std::getline(cells, question, ',');
        std::getline(cells, method, ',');
        std::getline(cells, who, ',');
        std::getline(cells, stimulus, ',');
        EXPECT_EQ(++seen[block + "|" + method + "|" + who + "|" + stimulus], 1) << line;
        pair_rows += block == "pc" ? 1 : 0;
    }
    EXPECT_EQ(pair_rows, 3 * (2 + 2));
    EXPECT_EQ(seen.count("pc|Thurstone Case V (probit)|(pooled)|a"), 1u);
    EXPECT_NE(
        s.files.back().second.find("quadruple,differs_more,MLDS (probit GLM; psi_p = "
                                   "1),(pooled),s8,1,1,"),
        std::string::npos);
}

TEST(ScalingReport, NothingToScaleGivesNoSection) {
    EXPECT_TRUE(scaling_section({}, {}).blocks.empty());
}

}  // namespace
}  // namespace lucent::analysis
