// A small JSON writer (manifest.json, sidecars). Keys keep insertion order.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

namespace orogen {

class JsonWriter {
public:
    JsonWriter& begin_object();
    JsonWriter& end_object();
    JsonWriter& begin_array();
    JsonWriter& end_array();
    JsonWriter& key(std::string_view k);
    JsonWriter& value(std::string_view v);
    JsonWriter& value(const char* v) { return value(std::string_view(v)); }
    JsonWriter& value(double v);
    JsonWriter& value(std::int64_t v);
    JsonWriter& value(std::uint64_t v);
    JsonWriter& value(int v) { return value(std::int64_t(v)); }
    JsonWriter& value(bool v);
    JsonWriter& null();
    const std::string& str() const { return out_; }

private:
    void comma();
    void indent();
    std::string out_;
    int depth_ = 0;
    bool first_ = true;
    bool after_key_ = false;
};

std::string json_escape(std::string_view s);

}  // namespace orogen
