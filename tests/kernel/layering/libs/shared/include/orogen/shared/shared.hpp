// The fixture library's one header: its namespace names its folder, as the rule asks.
#pragma once
namespace orogen::shared::detail {}
namespace orogen::shared {}
