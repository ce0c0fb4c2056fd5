#include "analysis/data/label.h"

#include <mutex>
#include <unordered_set>

namespace lucent::analysis {
namespace {

struct TextHash {
    using is_transparent = void;
    std::size_t operator()(std::string_view text) const noexcept {
        return std::hash<std::string_view>{}(text);
    }
};

struct Pool {
    std::mutex mutex;
    // Nodes never move, so the pointers labels hold stay valid.
    std::unordered_set<std::string, TextHash, std::equal_to<>> texts;
};

Pool& pool() {
    static Pool* instance =
        new Pool;  // never destroyed: labels outlive static destructors
    return *instance;
}

const std::string* intern(std::string_view text) {
    Pool& p = pool();
    std::lock_guard lock(p.mutex);
    const auto found = p.texts.find(text);
    if (found != p.texts.end()) return &*found;
    return &*p.texts.emplace(text).first;
}

const std::string* empty_text() {
    static const std::string* const empty = intern({});
    return empty;
}

}  // namespace

Label::Label() : text_(empty_text()) {}
Label::Label(std::string_view text) : text_(text.empty() ? empty_text() : intern(text)) {}

}  // namespace lucent::analysis
