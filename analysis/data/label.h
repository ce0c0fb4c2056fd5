#pragma once
// A text label of the long table (participant code, stimulus id, factor, level or
// question name), interned: each distinct text is stored once for the life of the
// process, and a label is one pointer to it. A million ratings then cost 8 bytes per
// field instead of a std::string each (the difference between 64 and 184 MB of rows),
// and equal labels compare by pointer. A study has thousands of distinct labels, not
// millions, so the pool never needs freeing. Thread-safe.
#include <compare>
#include <cstddef>
#include <functional>
#include <ostream>
#include <string>
#include <string_view>

namespace lucent::analysis {

class Label {
public:
    Label();
    Label(std::string_view
              text);  // NOLINT: implicit, so `row.level = "18"` reads naturally
    Label(const std::string& text) : Label(std::string_view(text)) {}
    Label(const char* text) : Label(std::string_view(text)) {}

    const std::string& str() const { return *text_; }
    operator const std::string&() const { return *text_; }  // NOLINT: read as a string
    operator std::string_view() const { return *text_; }    // NOLINT
    bool empty() const { return text_->empty(); }
    std::size_t size() const { return text_->size(); }
    const char* c_str() const { return text_->c_str(); }

    // Interning makes equal texts the same pointer.
    friend bool operator==(const Label& a, const Label& b) { return a.text_ == b.text_; }
    friend bool operator==(const Label& a, std::string_view b) { return *a.text_ == b; }
    friend bool operator==(const Label& a, const std::string& b) { return *a.text_ == b; }
    friend bool operator==(const Label& a, const char* b) { return *a.text_ == b; }
    friend std::strong_ordering operator<=>(const Label& a, const Label& b) {
        return a.text_ == b.text_ ? std::strong_ordering::equal : *a.text_ <=> *b.text_;
    }
    friend std::string operator+(const Label& a, const std::string& b) {
        return *a.text_ + b;
    }
    friend std::string operator+(const std::string& a, const Label& b) {
        return a + *b.text_;
    }
    friend std::string operator+(const Label& a, const char* b) { return *a.text_ + b; }
    friend std::string operator+(const char* a, const Label& b) { return a + *b.text_; }
    friend std::ostream& operator<<(std::ostream& out, const Label& label) {
        return out << *label.text_;
    }

    // Identity, for hashing: equal labels have equal addresses.
    const void* identity() const { return text_; }

private:
    const std::string* text_;
};

}  // namespace lucent::analysis

template <>
struct std::hash<lucent::analysis::Label> {
    std::size_t operator()(const lucent::analysis::Label& label) const noexcept {
        return std::hash<const void*>{}(label.identity());
    }
};
