#include "core/json/element_json_plan.hpp"

#include <algorithm>
#include <charconv>
#include <deque>
#include <map>
#include <optional>
#include <vector>

#include "core/json/element_json_text.hpp"
#include "core/json/namedarray_shape.hpp"
#include "core/json/value_json.hpp"
#include "core/json/utf8.hpp"
#include "core/value/element_layout.hpp"
#include "core/value/named_type.hpp"
#include "core/value/pack_value.hpp"

namespace rr::element_json_text {

using robdef::ArrayKind;
using robdef::ContainerKind;
using robdef::NamedTypeKind;
using robdef::TypeDefinition;

namespace {

struct Node;

/// A field of a struct or pod, or a member of a namedarray item: `"name":` and how to render it.
struct Field {
    std::string name;
    std::string key;  ///< `"name":`
    const Node* node = nullptr;
    /// Pod field declared multi-dim: `,"dims":[…]}` closes its {"array": …} object.
    std::string dims_suffix;
};

/// A namedarray item's fields in nlohmann's key order, with where each sits in the item.
struct NamedArrayItem {
    struct Member {
        std::string key;
        std::size_t offset = 0;  ///< elements from the item's start
        std::size_t count = 1;
        bool array = false;
        const NamedArrayItem* nested = nullptr;
    };
    std::size_t width = 0;
    std::vector<Member> members;
};

/// What a struct, pod or namedarray type renders with (one per definition, shared by its uses).
struct Body {
    /// The definition is one the plan does not render itself (a duplicate field name, an invalid
    /// pod, …): its uses go through the general path.
    bool failed = false;
    std::string qualified_name;
    std::vector<Field> fields;  ///< struct, pod: sorted by name
    DataTypes element_type = DataTypes::void_t;  ///< namedarray
    std::size_t element_size = 0;
    const NamedArrayItem* item = nullptr;
};

enum class Kind {
    null_value, numeric, numeric_multidim, string, enumeration, structure, pod, namedarray, list, map_int32, map_string,
    general  ///< unpack_value → value_to_json → dump for this part alone (varvalue, multi-dim pod arrays, …)
};

struct Node {
    Kind kind = Kind::null_value;
    TypeDefinition type;  ///< numeric, pod, namedarray: the element type and count rule; general: the type
    std::string context;  ///< where `type`'s unqualified names resolve (general, and failed bodies)
    const Body* body = nullptr;
    const Node* item = nullptr;  ///< containers
};

}  // namespace

struct Plan::Graph {
    std::deque<Node> nodes;
    std::deque<Body> bodies;
    std::deque<NamedArrayItem> items;
    const Node* root = nullptr;
    const robdef::TypeLookup* lookup = nullptr;  ///< for the general parts
    Limits limits;
};

void append_string(std::string& out, std::string_view s) {
    static constexpr char kHex[] = "0123456789abcdef";
    out += '"';
    std::size_t run = 0;  // start of the bytes not yet copied
    for (std::size_t i = 0; i < s.size(); ++i) {
        const auto c = static_cast<unsigned char>(s[i]);
        if (c >= 0x20 && c != '"' && c != '\\') continue;
        out.append(s.data() + run, i - run);
        run = i + 1;
        switch (c) {
            case '"': out += "\\\""; break;
            case '\\': out += "\\\\"; break;
            case '\b': out += "\\b"; break;
            case '\f': out += "\\f"; break;
            case '\n': out += "\\n"; break;
            case '\r': out += "\\r"; break;
            case '\t': out += "\\t"; break;
            default: {
                const char u[] = {'\\', 'u', '0', '0', kHex[c >> 4], kHex[c & 0xF]};
                out.append(u, sizeof u);
            }
        }
    }
    out.append(s.data() + run, s.size() - run);
    out += '"';
}

namespace {

// --- compiling ----------------------------------------------------------------------------------

class Compiler {
public:
    Compiler(Plan::Graph& g, const robdef::TypeLookup& lookup) : g_(g), lookup_(lookup) {}

    /// The node of `t`: rendered by the plan where it can, else a general node.
    const Node* node(const TypeDefinition& t, std::string_view ctx, int depth);

private:
    Node& add(Kind kind, const TypeDefinition& t, std::string_view ctx = {}) {
        Node& n = g_.nodes.emplace_back();
        n.kind = kind;
        n.type = t;
        n.context = ctx;
        return n;
    }
    const Node* native(const TypeDefinition& t, std::string_view ctx, int depth);
    Body& new_body(const NamedType& nt) {
        Body& b = g_.bodies.emplace_back();
        b.qualified_name = nt.qualified_name;
        bodies_.emplace(nt.entry, &b);
        return b;
    }
    const Node* named(const TypeDefinition& t, std::string_view ctx, int depth);
    const Body* structure(const NamedType& nt, int depth);
    const Body* pod(const NamedType& nt, int depth);
    bool pod_fields(Body& b, const std::vector<PodFieldPlan>& plans, int depth);
    const Body* namedarray(const NamedType& nt);
    const NamedArrayItem* namedarray_item(const NamedArrayShape& shape);
    static bool sort_fields(std::vector<Field>& fields);

    Plan::Graph& g_;
    const robdef::TypeLookup& lookup_;
    std::map<const robdef::ServiceEntryDefinition*, const Body*> bodies_;  // cycles end here
};

// Object keys as nlohmann orders and writes them; false for a duplicate (the general path keeps one
// of them) or a name that is not valid UTF-8.
bool Compiler::sort_fields(std::vector<Field>& fields) {
    std::sort(fields.begin(), fields.end(), [](const Field& a, const Field& b) { return a.name < b.name; });
    for (std::size_t i = 0; i < fields.size(); ++i) {
        if (i && fields[i].name == fields[i - 1].name) return false;
        if (!is_valid_utf8(fields[i].name)) return false;
        append_string(fields[i].key, fields[i].name);
        fields[i].key += ':';
    }
    return true;
}

const Node* Compiler::node(const TypeDefinition& t, std::string_view ctx, int depth) {
    if (const Node* n = native(t, ctx, depth)) return n;
    return &add(Kind::general, t, ctx);
}

const Node* Compiler::native(const TypeDefinition& t, std::string_view ctx, int depth) {
    if (depth > 64) return nullptr;
    if (t.container != ContainerKind::none) {
        Kind kind;
        switch (t.container) {
            case ContainerKind::list: kind = Kind::list; break;
            case ContainerKind::map_int32: kind = Kind::map_int32; break;
            case ContainerKind::map_string: kind = Kind::map_string; break;
            default: return nullptr;  // generator
        }
        const Node* item = node(without_container(t), ctx, depth + 1);
        Node& n = add(kind, t);
        n.item = item;
        return &n;
    }
    if (is_numeric(t.base)) return &add(t.array == ArrayKind::multidimarray ? Kind::numeric_multidim : Kind::numeric, t);
    switch (t.base) {
        case DataTypes::void_t: return &add(Kind::null_value, t);
        case DataTypes::string_t: return t.array == ArrayKind::none ? &add(Kind::string, t) : nullptr;
        case DataTypes::namedtype_t: return named(t, ctx, depth);
        default: return nullptr;  // varvalue, and what is not a value type
    }
}

const Node* Compiler::named(const TypeDefinition& t, std::string_view ctx, int depth) {
    auto nt = resolve_named_type(t, lookup_, ctx);
    if (!nt) return nullptr;
    switch (nt->kind) {
        case NamedTypeKind::enumeration: return t.array == ArrayKind::none ? &add(Kind::enumeration, t) : nullptr;
        case NamedTypeKind::structure: {
            if (t.array != ArrayKind::none) return nullptr;
            const Body* b = structure(*nt, depth);
            if (b->failed) return nullptr;
            Node& n = add(Kind::structure, t, ctx);  // a cycle may see its body fail later: ctx for that
            n.body = b;
            return &n;
        }
        case NamedTypeKind::pod:
        case NamedTypeKind::namedarray: {
            if (t.array == ArrayKind::multidimarray) return nullptr;
            const bool is_pod = nt->kind == NamedTypeKind::pod;
            const Body* b = is_pod ? pod(*nt, depth) : namedarray(*nt);
            if (b->failed) return nullptr;
            Node& n = add(is_pod ? Kind::pod : Kind::namedarray, t, ctx);
            n.body = b;
            return &n;
        }
        default: return nullptr;
    }
}

// Bodies are never null: one that cannot be rendered here is marked failed (a struct in a cycle may
// already be referred to by its own fields' nodes, which then take the general path).
const Body* Compiler::structure(const NamedType& nt, int depth) {
    if (auto it = bodies_.find(nt.entry); it != bodies_.end()) return it->second;
    Body& b = new_body(nt);
    for (const auto& m : nt.entry->members) {
        if (m.kind != robdef::MemberKind::field) continue;
        b.fields.push_back(Field{m.name, {}, node(m.type, nt.service->name, depth + 1), {}});
    }
    b.failed = !sort_fields(b.fields);
    return &b;
}

const Body* Compiler::pod(const NamedType& nt, int depth) {
    if (auto it = bodies_.find(nt.entry); it != bodies_.end()) return it->second;
    Body& b = new_body(nt);
    auto plans = pod_field_plans(nt, lookup_);
    b.failed = !plans || !pod_fields(b, *plans, depth);
    return &b;
}

// A pod's fields; false when one of them is not rendered here (then the whole pod is general).
bool Compiler::pod_fields(Body& b, const std::vector<PodFieldPlan>& plans, int depth) {
    for (const PodFieldPlan& plan : plans) {
        const TypeDefinition& wt = plan.wire_type;
        Field f{plan.member->name, {}, nullptr, {}};
        if (plan.multidim) {
            // Travels as a fixed 1-D array of the dims' product: pod_field_wire_type gives [0] (no
            // rule) when the dims overflow, which the general path then refuses.
            if (wt.array_length.empty() || wt.array_length[0] <= 0 || plan.dims.empty()) return false;
            f.dims_suffix = ",\"dims\":[";
            for (std::size_t i = 0; i < plan.dims.size(); ++i) {
                if (i) f.dims_suffix += ',';
                f.dims_suffix += std::to_string(plan.dims[i]);
            }
            f.dims_suffix += "]}";
        }
        if (is_numeric(wt.base)) {
            f.node = &add(Kind::numeric, wt);
        } else if (plan.named.kind == NamedTypeKind::pod) {
            const Body* inner = pod(plan.named, depth + 1);
            if (inner->failed) return false;
            Node& n = add(Kind::pod, wt);
            n.body = inner;
            f.node = &n;
        } else if (plan.named.kind == NamedTypeKind::namedarray) {
            const Body* inner = namedarray(plan.named);
            if (inner->failed) return false;
            Node& n = add(Kind::namedarray, wt);
            n.body = inner;
            f.node = &n;
        } else {
            return false;
        }
        b.fields.push_back(std::move(f));
    }
    return sort_fields(b.fields);
}

const Body* Compiler::namedarray(const NamedType& nt) {
    if (auto it = bodies_.find(nt.entry); it != bodies_.end()) return it->second;
    Body& b = new_body(nt);
    b.failed = true;
    auto layout = namedarray_layout(nt, lookup_);
    auto shape = namedarray_shape(nt, lookup_);
    if (!layout || !shape) return &b;
    // The general path unpacks with the layout and renders with the shape: they must agree.
    if ((*shape)->width != layout->elements_per_item || (*shape)->element_type != layout->element_type) return &b;
    b.item = namedarray_item(**shape);
    if (!b.item) return &b;
    b.element_type = layout->element_type;
    b.element_size = data_type_size(layout->element_type);
    b.failed = false;
    return &b;
}

const NamedArrayItem* Compiler::namedarray_item(const NamedArrayShape& shape) {
    NamedArrayItem& item = g_.items.emplace_back();
    item.width = shape.width;
    std::size_t offset = 0;
    std::vector<Field> names;  // for the key order and the duplicate check
    for (const auto& m : shape.members) {
        NamedArrayItem::Member im;
        im.offset = offset;
        im.count = m.count;
        im.array = m.array;
        if (m.nested) {
            im.nested = namedarray_item(*m.nested);
            if (!im.nested) return nullptr;
            offset += m.count * m.nested->width;
        } else {
            offset += m.count;
        }
        names.push_back(Field{std::string(m.name), {}, nullptr, {}});
        item.members.push_back(std::move(im));
    }
    if (offset != shape.width) return nullptr;
    // Sort the members by name, carrying their offsets along.
    std::vector<std::size_t> order(item.members.size());
    for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
    std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return names[a].name < names[b].name; });
    std::vector<NamedArrayItem::Member> sorted;
    sorted.reserve(order.size());
    for (std::size_t k = 0; k < order.size(); ++k) {
        const std::string& name = names[order[k]].name;
        if (k && name == names[order[k - 1]].name) return nullptr;
        if (!is_valid_utf8(name)) return nullptr;
        NamedArrayItem::Member m = std::move(item.members[order[k]]);
        append_string(m.key, name);
        m.key += ':';
        sorted.push_back(std::move(m));
    }
    item.members = std::move(sorted);
    return &item;
}

// --- rendering ----------------------------------------------------------------------------------

class Renderer {
public:
    Renderer(std::string& out, const Plan::Graph& g, bool omit_null_members)
        : out_(out), g_(g), max_depth_(g.limits.max_nesting_depth), omit_null_members_(omit_null_members) {}

    bool render(const Node& n, const MessageElement& e);

private:
    struct Depth {
        explicit Depth(std::size_t& d) : d_(d) { ++d_; }
        ~Depth() { --d_; }
        std::size_t& d_;
    };

    bool general(const Node& n, const MessageElement& e);
    bool numeric_multidim(const Node& n, const MessageElement& e);
    bool structure(const Node& n, const MessageElement& e);
    bool pod(const Node& n, const MessageElement& e);
    bool object(const Body& b, const MessageElement& e);
    bool field(const Field& f, const MessageElement& e);
    bool namedarray(const Node& n, const MessageElement& e);
    void namedarray_object(const NamedArrayItem& item, const std::byte* data, DataTypes type, std::size_t size);
    bool list(const Node& n, const MessageElement& e);
    bool map_int32(const Node& n, const MessageElement& e);
    bool map_string(const Node& n, const MessageElement& e);

    /// After a member written from `mark` on (its ',' and key) with its value from `value_at` on: with
    /// omit_null_members_ a null value takes the member out again. Returns whether the member stays.
    bool keep_member(std::size_t mark, std::size_t value_at) {
        if (!omit_null_members_ || out_.size() - value_at != 4 || out_.compare(value_at, 4, "null") != 0) return true;
        out_.resize(mark);
        return false;
    }

    std::string& out_;
    const Plan::Graph& g_;
    std::size_t depth_ = 0;
    std::size_t max_depth_;
    const bool omit_null_members_;
};

bool Renderer::render(const Node& n, const MessageElement& e) {
    // Counts at least every level the general path counts (unpack_value and value_to_json each stop at
    // Limits::max_nesting_depth), so a value rendered here never meets their depth error.
    Depth d(depth_);
    if (depth_ > max_depth_) return false;
    if (n.body && n.body->failed) return general(n, e);
    const bool nullable = n.kind == Kind::structure || n.kind == Kind::list || n.kind == Kind::map_int32 ||
                          n.kind == Kind::map_string;
    if (nullable && e.type == DataTypes::void_t) {
        out_ += "null";
        return true;
    }
    switch (n.kind) {
        case Kind::general: return general(n, e);
        case Kind::null_value: out_ += "null"; return true;
        case Kind::numeric: return append(out_, e, n.type);
        case Kind::numeric_multidim: return numeric_multidim(n, e);
        case Kind::string: {
            if (e.type != DataTypes::string_t) return false;
            std::string_view s(reinterpret_cast<const char*>(e.data.data()), e.data.size());
            if (!is_valid_utf8(s)) return false;
            append_string(out_, s);
            return true;
        }
        case Kind::enumeration: {
            if (e.type != DataTypes::int32_t || e.data.size() != sizeof(std::int32_t)) return false;
            append_number(out_, DataTypes::int32_t, e.data.data());
            return true;
        }
        case Kind::structure: return structure(n, e);
        case Kind::pod: return pod(n, e);
        case Kind::namedarray: return namedarray(n, e);
        case Kind::list: return list(n, e);
        case Kind::map_int32: return map_int32(n, e);
        case Kind::map_string: return map_string(n, e);
    }
    return false;
}

// This part alone the general way. Its own depth count starts at this node, so it gets the levels left
// (at most what the general path over the whole value would leave it: depth_ counts at least as many).
bool Renderer::general(const Node& n, const MessageElement& e) {
    Limits limits = g_.limits;
    limits.max_nesting_depth = max_depth_ - (depth_ - 1);
    auto v = unpack_value(e, n.type, *g_.lookup, n.context, limits);
    if (!v) return false;
    auto j = value_to_json(*v, n.type, *g_.lookup, n.context, limits);
    if (!j) return false;
    out_ += j->dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
    return true;
}

bool Renderer::numeric_multidim(const Node& n, const MessageElement& e) {
    if (e.type != DataTypes::multidimarray_t) return false;
    const MessageElement* dims = e.find("dims");
    const MessageElement* array = e.find("array");
    if (!dims || !array || dims->type != DataTypes::uint32_t || dims->data.empty() || dims->data.size() % 4 != 0)
        return false;
    const std::size_t item = data_type_size(n.type.base);
    if (array->type != n.type.base || array->data.size() % item != 0) return false;
    std::vector<std::uint32_t> d(dims->data.size() / 4);
    for (std::size_t i = 0; i < d.size(); ++i) d[i] = detail::load_item<std::uint32_t>(dims->data.data() + 4 * i);
    if (!check_dims(d, array->data.size() / item, n.type)) return false;
    TypeDefinition flat = n.type;
    flat.array = ArrayKind::array;
    flat.array_var_length = true;
    flat.array_length.clear();
    out_ += "{\"array\":";
    if (!append(out_, *array, flat)) return false;
    out_ += ",\"dims\":[";
    for (std::size_t i = 0; i < d.size(); ++i) {
        if (i) out_ += ',';
        append_number(out_, DataTypes::uint32_t, dims->data.data() + 4 * i);
    }
    out_ += "]}";
    return true;
}

bool Renderer::structure(const Node& n, const MessageElement& e) {
    const Body& b = *n.body;
    if (e.type != DataTypes::structure_t || e.type_name != b.qualified_name) return false;
    return object(b, e);
}

// `{"field":value,…}` of a struct or pod item: each field is the first child of its name.
bool Renderer::object(const Body& b, const MessageElement& e) {
    out_ += '{';
    bool first = true;
    for (std::size_t i = 0; i < b.fields.size(); ++i) {
        const Field& f = b.fields[i];
        const MessageElement* c = e.find(f.name);
        if (!c) return false;
        const std::size_t mark = out_.size();
        if (!first) out_ += ',';
        out_ += f.key;
        const std::size_t value_at = out_.size();
        if (!field(f, *c)) return false;
        if (keep_member(mark, value_at)) first = false;
    }
    out_ += '}';
    return true;
}

bool Renderer::pod(const Node& n, const MessageElement& e) {
    const Body& b = *n.body;
    if (e.type != DataTypes::pod_array_t || e.type_name != b.qualified_name) return false;
    if (!check_count(e.elements.size(), n.type)) return false;
    const bool scalar = n.type.array == ArrayKind::none;
    if (!scalar) out_ += '[';
    for (std::size_t i = 0; i < e.elements.size(); ++i) {
        const MessageElement& item = e.elements[i];
        auto number = element_number(item);
        if (!number || static_cast<std::size_t>(*number) != i || item.type != DataTypes::pod_t) return false;
        if (i) out_ += ',';
        if (!object(b, item)) return false;
    }
    if (!scalar) out_ += ']';
    return true;
}

// A pod field declared multi-dim is {"array": items, "dims": declared}; every other field is its node.
bool Renderer::field(const Field& f, const MessageElement& e) {
    if (f.dims_suffix.empty()) return render(*f.node, e);
    out_ += "{\"array\":";
    if (!render(*f.node, e)) return false;
    out_ += f.dims_suffix;
    return true;
}

bool Renderer::namedarray(const Node& n, const MessageElement& e) {
    const Body& b = *n.body;
    if (e.type != DataTypes::namedarray_array_t || e.type_name != b.qualified_name) return false;
    const MessageElement* array = e.find("array");
    if (!array || array->type != b.element_type || array->data.size() % b.element_size != 0) return false;
    const std::size_t elements = array->data.size() / b.element_size;
    const std::size_t width = b.item->width;
    if (elements % width != 0) return false;
    const std::size_t items = elements / width;
    if (!check_count(items, n.type)) return false;
    const bool scalar = n.type.array == ArrayKind::none;
    if (!scalar) out_ += '[';
    for (std::size_t i = 0; i < items; ++i) {
        if (i) out_ += ',';
        namedarray_object(*b.item, array->data.data() + i * width * b.element_size, b.element_type, b.element_size);
    }
    if (!scalar) out_ += ']';
    return true;
}

void Renderer::namedarray_object(const NamedArrayItem& item, const std::byte* data, DataTypes type, std::size_t size) {
    out_ += '{';
    for (std::size_t k = 0; k < item.members.size(); ++k) {
        const auto& m = item.members[k];
        if (k) out_ += ',';
        out_ += m.key;
        if (m.array) out_ += '[';
        const std::size_t step = m.nested ? m.nested->width : 1;
        for (std::size_t j = 0; j < m.count; ++j) {
            if (j) out_ += ',';
            const std::byte* at = data + (m.offset + j * step) * size;
            if (m.nested)
                namedarray_object(*m.nested, at, type, size);
            else
                append_number(out_, type, at);
        }
        if (m.array) out_ += ']';
    }
    out_ += '}';
}

bool Renderer::list(const Node& n, const MessageElement& e) {
    if (e.type != DataTypes::list_t) return false;
    out_ += '[';
    for (std::size_t i = 0; i < e.elements.size(); ++i) {
        auto number = element_number(e.elements[i]);
        if (!number || static_cast<std::size_t>(*number) != i) return false;
        if (i) out_ += ',';
        if (!render(*n.item, e.elements[i])) return false;
    }
    out_ += ']';
    return true;
}

bool Renderer::map_int32(const Node& n, const MessageElement& e) {
    if (e.type != DataTypes::vector_t) return false;
    struct Key {
        char text[12];
        std::uint8_t size;
        const MessageElement* item;
        std::string_view view() const { return {text, size}; }
    };
    std::vector<Key> keys(e.elements.size());
    for (std::size_t i = 0; i < keys.size(); ++i) {
        auto number = element_number(e.elements[i]);
        if (!number) return false;
        keys[i].size = static_cast<std::uint8_t>(std::to_chars(keys[i].text, keys[i].text + 12, *number).ptr - keys[i].text);
        keys[i].item = &e.elements[i];
    }
    // nlohmann keeps the keys as strings, in their order ("10" before "9").
    std::sort(keys.begin(), keys.end(), [](const Key& a, const Key& b) { return a.view() < b.view(); });
    out_ += '{';
    bool first = true;
    for (std::size_t i = 0; i < keys.size(); ++i) {
        if (i && keys[i].view() == keys[i - 1].view()) return false;  // duplicate key: the general path refuses it
        const std::size_t mark = out_.size();
        if (!first) out_ += ',';
        out_ += '"';
        out_ += keys[i].view();
        out_ += "\":";
        const std::size_t value_at = out_.size();
        if (!render(*n.item, *keys[i].item)) return false;
        if (keep_member(mark, value_at)) first = false;
    }
    out_ += '}';
    return true;
}

bool Renderer::map_string(const Node& n, const MessageElement& e) {
    if (e.type != DataTypes::dictionary_t) return false;
    std::vector<const MessageElement*> items(e.elements.size());
    for (std::size_t i = 0; i < items.size(); ++i) {
        const MessageElement& c = e.elements[i];
        if (c.number || !is_valid_utf8(c.name)) return false;
        items[i] = &c;
    }
    std::sort(items.begin(), items.end(), [](const MessageElement* a, const MessageElement* b) { return a->name < b->name; });
    out_ += '{';
    bool first = true;
    for (std::size_t i = 0; i < items.size(); ++i) {
        if (i && items[i]->name == items[i - 1]->name) return false;
        const std::size_t mark = out_.size();
        if (!first) out_ += ',';
        append_string(out_, items[i]->name);
        out_ += ':';
        const std::size_t value_at = out_.size();
        if (!render(*n.item, *items[i])) return false;
        if (keep_member(mark, value_at)) first = false;
    }
    out_ += '}';
    return true;
}

}  // namespace

Plan::Plan(std::unique_ptr<Graph> graph) : graph_(std::move(graph)) {}
Plan::~Plan() = default;

std::shared_ptr<const Plan> Plan::compile(const TypeDefinition& type, const robdef::TypeLookup& lookup,
                                          std::string_view context_service, const Limits& limits) {
    auto g = std::make_unique<Graph>();
    g->lookup = &lookup;
    g->limits = limits;
    Compiler c(*g, lookup);
    g->root = c.node(type, context_service, 0);
    if (g->root->kind == Kind::general || (g->root->body && g->root->body->failed))
        return nullptr;  // nothing here to do better than the caller's own general path
    return std::make_shared<const Plan>(std::move(g));
}

bool Plan::append(std::string& out, const MessageElement& element, bool omit_null_members) const {
    const std::size_t at = out.size();
    Renderer r(out, *graph_, omit_null_members);
    if (r.render(*graph_->root, element)) return true;
    out.resize(at);
    return false;
}

}  // namespace rr::element_json_text
