#pragma once
// docs/fields.md: the reference of every result field, generated from the field declarations beside
// the result structs (core/fields.hpp). `piezobench fields --out docs/fields.md` writes it;
// FieldReference.DocsAreCurrent fails when the committed file is stale.
#include <string>

namespace piezobench::campaign {

// The whole document (Markdown): every struct reachable from UnitAnalysis, CampaignResult's batch,
// IFF study and super element comparison, and ident::LoopMetrics (what `ident.loop_metrics` returns),
// one table each.
std::string field_reference_markdown();

}  // namespace piezobench::campaign
