// Segmentation label tables (splat/settings.h, Labels).
#include <algorithm>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "splat/error.h"
#include "splat/settings.h"

namespace splat {

glm::vec4 Labels::shown(int label) const {
    if (label <= 0 || label >= int(table.size())) return glm::vec4(0.0f);
    if (!selection.empty() &&
        std::find(selection.begin(), selection.end(), label) == selection.end())
        return glm::vec4(0.0f);
    return table[std::size_t(label)];
}

Labels Labels::load(const std::string& colours, const std::string& names, float opacity) {
    Labels l;
    l.enabled = true;
    auto ends = [](const std::string& s, const std::string& e) {
        return s.size() >= e.size() && s.compare(s.size() - e.size(), e.size(), e) == 0;
    };
    std::ifstream in(colours, std::ios::binary);
    if (!in) throw Error(colours + ": cannot open label colour table");
    if (ends(colours, ".json")) {
        nlohmann::json j;
        try {
            in >> j;
            for (const auto& e : j.at("labels")) {
                const int index = e.at("index").get<int>();
                if (index < 0 || index > 65535)
                    throw Error(colours + ": label index outside 0..65535");
                if (int(l.table.size()) <= index) {
                    l.table.resize(std::size_t(index) + 1, glm::vec4(0.0f));
                    l.names.resize(std::size_t(index) + 1);
                }
                const auto& c = e.at("color");
                l.table[std::size_t(index)] =
                    glm::vec4(c.at(0).get<float>(), c.at(1).get<float>(), c.at(2).get<float>(),
                              e.value("opacity", opacity));
                l.names[std::size_t(index)] = e.value("name", "");
            }
        } catch (const nlohmann::json::exception& e) {
            throw Error(colours + ": bad label table (" + std::string(e.what()) + ")");
        }
    } else {
        // mricron .lut: 256 red bytes, then 256 green, then 256 blue.
        std::vector<unsigned char> b((std::istreambuf_iterator<char>(in)), {});
        if (b.size() != 768) throw Error(colours + ": a .lut must hold 768 bytes (256 x RGB)");
        l.table.resize(256);
        for (int n = 0; n < 256; ++n)
            l.table[n] =
                glm::vec4(b[n] / 255.0f, b[256 + n] / 255.0f, b[512 + n] / 255.0f, opacity);
        l.names.resize(256);
    }
    if (!l.table.empty()) l.table[0] = glm::vec4(0.0f);  // background
    if (!names.empty()) {
        std::ifstream t(names);
        if (!t) throw Error(names + ": cannot open label names");
        std::string line;
        while (std::getline(t, line)) {
            std::istringstream ls(line);
            int index;
            std::string name;
            if (!(ls >> index >> name) || index < 0 || index >= int(l.table.size())) continue;
            if (int(l.names.size()) <= index) l.names.resize(std::size_t(index) + 1);
            l.names[std::size_t(index)] = name;
        }
    }
    return l;
}

}  // namespace splat
