#pragma once
// docs/fields.md: the reference of every result field, generated from the field declarations beside
// the result structs (core/fields.hpp). `piezobench fields --out docs/fields.md` writes it
// (with the program's further tables); FieldReferenceCli.DocsAreCurrent fails when the committed file is stale.
#include <functional>
#include <set>
#include <string>

namespace piezobench::campaign {

// The whole document (Markdown): every struct reachable from UnitAnalysis, CampaignResult's batch,
// IFF study and super element comparison, and ident::LoopMetrics (what `ident.loop_metrics` returns),
// one table each.
// more(out, done): the caller's further tables (field_table<S>(out, done)), appended after
// campaign's; the program adds the modules campaign does not depend on (app/field_reference.cpp:
// rt's loop report, limits, I/O and timing), and docs/fields.md is that whole document.
std::string field_reference_markdown(const std::function<void(std::string& out, std::set<std::string>& done)>& more = {});

}  // namespace piezobench::campaign
