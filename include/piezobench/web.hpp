#pragma once
// The web module (`qualify --ui`, `station serve`; docs/station.md, "The live page"): the HTTP
// server, the live hub with its per-client mailboxes, the station's page and endpoints, the page's
// operator.
#include "piezobench/web/http_server.hpp"
#include "piezobench/web/live_hub.hpp"
#include "piezobench/web/station_site.hpp"
#include "piezobench/web/web_operator.hpp"
