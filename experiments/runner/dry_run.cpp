// `gilab run --dry-run`: the runs as a table, the swept parameters first (docs/experiments.md).
#include "experiments/runner/dry_run.h"

#include <algorithm>
#include <cstdio>
#include <map>
#include <set>
#include <utility>

namespace gilab::exp {
namespace {

/** "[done]", "[todo]", or "[todo: invalid]" for a stored invalid run (redone). */
const char* dryRunState(const RunStore& store, const std::string& key) {
    const std::string status = store.storedStatus(key);
    if (isFinalStatus(status)) return "[done]";
    return status == "invalid" ? "[todo: invalid]" : "[todo]";
}

}  // namespace

// Swept = differs between two runs of one technique; the rest is printed once, above.
void printDryRun(const std::vector<const RunSpec*>& runs, const std::vector<std::string>& keys,
                 const RunStore& store) {
    using Cells = std::vector<std::pair<std::string, std::string>>;  // column, value in order
    std::vector<Cells> cells(runs.size());
    std::vector<std::string> techniques;  // in order of appearance
    for (size_t i = 0; i < runs.size(); ++i) {
        auto add = [&](const std::string& prefix, const ParamSet& values) {
            for (const ParamSpec& spec : values.specs())  // canonical text, as --set takes it
                cells[i].emplace_back(prefix + spec.name, values.getText(spec.name));
        };
        add("param.", runs[i]->params);
        add("shared.", runs[i]->shared);
        if (std::find(techniques.begin(), techniques.end(), runs[i]->techniqueId) ==
            techniques.end())
            techniques.push_back(runs[i]->techniqueId);
    }
    // A column is swept when two runs of one technique differ in it
    std::set<std::string> differs;
    std::map<std::string, std::map<std::string, std::string>> first;  // technique -> column
    for (size_t i = 0; i < runs.size(); ++i)
        for (const auto& [column, value] : cells[i]) {
            const auto [it, isNew] = first[runs[i]->techniqueId].emplace(column, value);
            if (!isNew && it->second != value) differs.insert(column);
        }
    // ... in spec order, param.* before shared.* (as results.csv)
    std::vector<std::string> swept;
    for (const Cells& row : cells)
        for (const auto& [column, value] : row)
            if (differs.count(column) &&
                std::find(swept.begin(), swept.end(), column) == swept.end())
                swept.push_back(column);
    std::stable_partition(swept.begin(), swept.end(),
                          [](const std::string& c) { return c.rfind("param.", 0) == 0; });
    // Constant columns: one line for those equal in every run, one per technique for the rest
    auto isSwept = [&](const std::string& c) {
        return std::find(swept.begin(), swept.end(), c) != swept.end();
    };
    std::vector<std::string> everywhere;
    if (!runs.empty())
        for (const auto& [column, value] : cells[0]) {
            bool same = !isSwept(column);
            for (const std::string& t : techniques) {
                const auto it = first[t].find(column);
                same = same && it != first[t].end() && it->second == value;
            }
            if (same) everywhere.push_back(column + "=" + value);
        }
    std::printf("# %zu runs; swept parameters are columns; constant for all runs:", runs.size());
    for (const std::string& c : everywhere)
        std::printf(" %s", c.c_str());
    std::printf("\n");
    for (const std::string& t : techniques) {
        std::string line;
        size_t row = 0;  // the technique's first run: its columns in spec order
        while (runs[row]->techniqueId != t)
            ++row;
        for (const auto& [column, value] : cells[row]) {
            const std::string cell = column + "=" + value;
            if (!isSwept(column) &&
                std::find(everywhere.begin(), everywhere.end(), cell) == everywhere.end())
                line += " " + cell;
        }
        if (!line.empty()) std::printf("# constant for %s runs:%s\n", t.c_str(), line.c_str());
    }
    std::printf("index\tkey\tstate\tscene\ttechnique");
    for (const std::string& c : swept)
        std::printf("\t%s", c.c_str());
    std::printf("\n");
    for (size_t i = 0; i < runs.size(); ++i) {
        std::printf("%zu\t%s\t%s\t%s\t%s", runs[i]->index, keys[i].substr(0, 12).c_str(),
                    dryRunState(store, keys[i]), runs[i]->scene->label.c_str(),
                    runs[i]->techniqueId.c_str());
        for (const std::string& c : swept) {
            std::string value;
            for (const auto& [column, v] : cells[i])
                if (column == c) value = v;
            std::printf("\t%s", value.c_str());
        }
        std::printf("\n");
    }
}

}  // namespace gilab::exp
