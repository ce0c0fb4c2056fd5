#pragma once
// The report as a tiny document model rendered to both Markdown and HTML, so the two
// never disagree, and the report's files by name (rendered in memory, written once all
// are checked).
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

namespace lucent::analysis {

struct Table {
    std::vector<std::string> header;
    std::vector<std::vector<std::string>> rows;
};

struct Block {
    enum Kind { kHeading, kParagraph, kTable, kPlot, kImages } kind;
    std::string text;  // heading/paragraph text, or plot file name
    Table table;
    std::string svg;
    int level = 2;
    struct Image {
        std::string caption;
        std::filesystem::path path;
    };
    std::vector<Image> images;  // kImages: thumbnails in a row
};

using ReportFiles = std::vector<std::pair<std::string, std::string>>;

}  // namespace lucent::analysis
