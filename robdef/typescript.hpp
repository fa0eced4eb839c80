// TypeScript declarations for service definitions (`rr-robdef ts`): one module per definition, typed
// the way the WebAssembly client package (wasm-client/) gives and takes values at run time
// (wasm-client/README.md "Values": js_values.cpp, js_numbers.cpp), and its member proxies typed by
// their value types (wasm-client/src/index.d.ts: Property<T>, Wire<T>, Pipe<T>, ...).
//
// Sans-IO: definitions in, text out; the caller (robdef/tools) reads and writes the files.
#pragma once

#include <string>
#include <string_view>

#include "robdef/service_definition.hpp"
#include "robdef/type_lookup.hpp"

namespace rr::robdef {

struct TypeScriptOptions {
    /// Module the member proxy types are imported from (`import type { Property, ... } from "…"`).
    std::string package = "robotraconteur-wasm";
};

/// One definition as an ES module, in two forms:
///  - `<service>.ts` (`source`): types, enums and constants in one TypeScript module, for an app's own
///    source tree (every build tool compiles or bundles it: tsc with outDir, esbuild, Vite, webpack);
///  - `<service>.d.ts` + `<service>.js` (`declarations`, `javascript`): the same as a package ships them
///    (the .js holds only the enums and constants, so `import type` of the module costs nothing).
struct TypeScriptModule {
    std::string file_stem;     ///< the service name: `com.robotraconteur.robotics.robot`
    std::string source;        ///< the .ts text
    std::string declarations;  ///< the .d.ts text
    std::string javascript;    ///< the .js text
};

/// Generates the module of `def`. Named types must be resolved (ServiceDefinitionSet::add does it) and
/// the set verified; types of other definitions are imported from `./<service>.js`, which the caller
/// generates too. `lookup` finds nested namedarrays (their element type decides the JS numbers).
/// Mapping (wasm-client/README.md "Values"):
///  - double/single/int8..uint32 → number; int64/uint64 → bigint; bool → boolean; c* → Complex;
///  - numeric arrays → Float64Array … BigUint64Array (bool[] → boolean[], complex → Complex[]);
///    multi-dim → MultiDimArray<that array>;
///  - string → string; enum → the union of its values (numbers); varvalue → VarValue | null;
///  - struct → its interface | null (the runtime gives null for a null struct, wherever it occurs);
///  - pod/namedarray → its interface; arrays of them → T[]; multi-dim → MultiDimArray<T[]>;
///  - {list} → Array<T> | null; {string} → Record<string, T> | null; {int32} → Map<number, T> | null;
///  - namedarray fields: scalars as their element type (number, or bigint for 64-bit elements),
///    fixed arrays as typed arrays of the element type.
/// Objects become interfaces extending ObjectBase, one member proxy type per member.
TypeScriptModule to_typescript(const ServiceDefinition& def, const TypeLookup& lookup, const TypeScriptOptions& options = {});

/// The identifier a service's namespace import gets in other modules: `com.robotraconteur.geometry`
/// → `com_robotraconteur_geometry`.
std::string typescript_namespace_name(std::string_view service_name);

}  // namespace rr::robdef
