#include "core/value/var_type.hpp"

#include "robdef/parser.hpp"

namespace rr {

using robdef::ArrayKind;
using robdef::ContainerKind;
using robdef::TypeDefinition;

std::string var_type_string(const Value& v) {
    switch (v.kind()) {
        case ValueKind::null: return "";
        case ValueKind::numeric:
            return std::string(data_type_keyword(v.get_if<NumericArray>()->type())) + "[]";
        case ValueKind::string: return "string";
        case ValueKind::multidim:
            return std::string(data_type_keyword(v.get_if<MultiDimArray>()->array.type())) + "[*]";
        case ValueKind::structure: return v.get_if<Structure>()->type_name;
        case ValueKind::pod: {
            auto* p = v.get_if<PodArray>();
            return p->type_name + (p->dims.empty() ? "[]" : "[*]");
        }
        case ValueKind::namedarray: {
            auto* n = v.get_if<NamedArray>();
            return n->type_name + (n->dims.empty() ? "[]" : "[*]");
        }
        case ValueKind::map_int32: return "varvalue{int32}";
        case ValueKind::map_string: return "varvalue{string}";
        case ValueKind::list: return "varvalue{list}";
        case ValueKind::enumeration: {
            auto* e = v.get_if<Enum>();
            return e->type_name.empty() ? "int32" : e->type_name;
        }
    }
    return "";
}

Result<TypeDefinition> parse_type_string(std::string_view text) {
    auto bad = [&](std::string_view why) {
        return fail(MessageErrorType::DataTypeError,
                    "invalid type string \"" + std::string(text) + "\": " + std::string(why));
    };
    auto t = robdef::parse_type(text);
    if (!t) return bad(t.error().message);
    switch (t->base) {
        case DataTypes::structure_t:
        case DataTypes::object_t:
        case DataTypes::varobject_t: return bad("not a value type");
        case DataTypes::void_t:
            if (t->array != ArrayKind::none || t->container != ContainerKind::none)
                return bad("void cannot be an array or container");
            break;
        case DataTypes::namedtype_t: {
            const std::string& n = t->type_name;
            if (n.empty() || n.back() == '.' || n.find("..") != std::string::npos) return bad("bad qualified name");
            break;
        }
        default: break;
    }
    if (t->container == ContainerKind::generator) return bad("a generator is not a value type");
    return t;
}

}  // namespace rr
