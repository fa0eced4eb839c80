#include "server/service/memory_member.hpp"

#include <limits>

#include "core/value/named_type.hpp"
#include "server/service/member_support.hpp"

namespace rr::server {

namespace {

RRError out_of_range() { return make_error(MessageErrorType::OutOfRange, "Index out of range"); }

/// Visits the contiguous runs (along the first dimension, column-major) of a block of `count` items
/// between a large array of dims `mem_dims` (block at `pos`) and a block array of dims `blk_dims` (block
/// at 0): fn(mem_offset, block_offset, run_items). Preconditions: bounds checked, all sizes equal.
template <class F>
void for_each_run(const std::vector<std::uint64_t>& mem_dims, const std::vector<std::uint64_t>& pos,
                  const std::vector<std::uint64_t>& blk_dims, const std::vector<std::uint64_t>& count, F&& fn) {
    const std::size_t n = count.size();
    for (auto c : count)
        if (c == 0) return;
    std::vector<std::uint64_t> mem_stride(n, 1), blk_stride(n, 1), idx(n, 0);
    for (std::size_t i = 1; i < n; ++i) {
        mem_stride[i] = mem_stride[i - 1] * mem_dims[i - 1];
        blk_stride[i] = blk_stride[i - 1] * blk_dims[i - 1];
    }
    for (;;) {
        std::uint64_t m = pos[0], b = 0;
        for (std::size_t i = 1; i < n; ++i) {
            m += (pos[i] + idx[i]) * mem_stride[i];
            b += idx[i] * blk_stride[i];
        }
        fn(static_cast<std::size_t>(m), static_cast<std::size_t>(b), static_cast<std::size_t>(count[0]));
        std::size_t i = 1;
        for (; i < n; ++i) {
            if (++idx[i] < count[i]) break;
            idx[i] = 0;
        }
        if (i >= n) return;
    }
}

/// Copies `items` numeric elements from src[s…] to dst[d…] (same numeric type).
void copy_numbers(NumericArray& dst, std::size_t d, const NumericArray& src, std::size_t s, std::size_t items) {
    dispatch_numeric(dst.type(), [&](auto tag) {
        using T = typename decltype(tag)::type;
        auto out = dst.mutable_span<T>();
        auto in = src.view<T>();
        for (std::size_t k = 0; k < items; ++k) out[d + k] = in[s + k];
    });
}

Result<std::vector<std::uint32_t>> to_u32_dims(const std::vector<std::uint64_t>& dims) {
    std::vector<std::uint32_t> out;
    out.reserve(dims.size());
    for (auto d : dims) {
        if (d > std::numeric_limits<std::uint32_t>::max()) return fail(out_of_range());
        out.push_back(static_cast<std::uint32_t>(d));
    }
    return out;
}

Result<std::vector<std::uint64_t>> read_u64_array(const MessageEntry& entry, std::string_view name) {
    auto e = detail::require_element(entry, name);
    if (!e) return e.take_error();
    if ((*e)->type != DataTypes::uint64_t) return fail(MessageErrorType::DataTypeMismatch, "Data type cast error");
    return read_array<std::uint64_t>(**e);
}

MessageElement u64_element(std::string name, const std::vector<std::uint64_t>& v, bool scalar) {
    if (scalar) return make_scalar_element<std::uint64_t>(std::move(name), v.empty() ? 0 : v[0]);
    return make_array_element<std::uint64_t>(std::move(name), std::span<const std::uint64_t>(v.data(), v.size()));
}

}  // namespace

/// The contents in a form that block copies can work on.
struct MemoryMember::Store {
    enum class Kind { numeric, namedarray, pod } kind = Kind::numeric;
    std::vector<std::uint64_t> dims;
    NumericArray numbers;      // numeric and namedarray: flat items
    std::size_t per_item = 1;  // numeric elements per namedarray item
    std::string type_name;     // pod / namedarray
    PodArray pods;

    std::size_t items() const {
        std::size_t n = 1;
        for (auto d : dims) n *= static_cast<std::size_t>(d);
        return n;
    }

    /// An empty block value of `count` items (dims = count for multi-dim).
    Value make_block(const std::vector<std::uint64_t>& count, bool multidim) const {
        std::size_t n = 1;
        for (auto c : count) n *= static_cast<std::size_t>(c);
        std::vector<std::uint32_t> d;
        if (multidim)
            for (auto c : count) d.push_back(static_cast<std::uint32_t>(c));
        switch (kind) {
            case Kind::numeric: {
                NumericArray a = NumericArray::zeros(numbers.type(), n);
                if (multidim) return Value(MultiDimArray{std::move(d), std::move(a)});
                return Value(std::move(a));
            }
            case Kind::namedarray:
                return Value(NamedArray{type_name, NumericArray::zeros(numbers.type(), n * per_item), std::move(d)});
            case Kind::pod: {
                PodArray p;
                p.type_name = type_name;
                p.field_names = pods.field_names;
                p.values.resize(n * p.field_names.size());
                p.count = n;
                p.dims = std::move(d);
                return Value(std::move(p));
            }
        }
        return Value();
    }

    /// Copies `items` items between this store and a block value (to_store: block → store).
    void copy(Value& block, std::size_t block_offset, std::size_t store_offset, std::size_t items, bool to_store) {
        switch (kind) {
            case Kind::numeric:
            case Kind::namedarray: {
                NumericArray* b = nullptr;
                if (auto* a = block.get_if<NumericArray>()) b = a;
                if (auto* m = block.get_if<MultiDimArray>()) b = &m->array;
                if (auto* na = block.get_if<NamedArray>()) b = &na->array;
                if (to_store)
                    copy_numbers(numbers, store_offset * per_item, *b, block_offset * per_item, items * per_item);
                else
                    copy_numbers(*b, block_offset * per_item, numbers, store_offset * per_item, items * per_item);
                return;
            }
            case Kind::pod: {
                auto* p = block.get_if<PodArray>();
                const std::size_t f = pods.field_names.size();
                for (std::size_t k = 0; k < items * f; ++k) {
                    if (to_store)
                        pods.values[store_offset * f + k] = p->values[block_offset * f + k];
                    else
                        p->values[block_offset * f + k] = pods.values[store_offset * f + k];
                }
                return;
            }
        }
    }

    Value as_value(bool multidim) const {
        std::vector<std::uint32_t> d;
        if (multidim)
            for (auto x : dims) d.push_back(static_cast<std::uint32_t>(x));
        switch (kind) {
            case Kind::numeric:
                if (multidim) return Value(MultiDimArray{std::move(d), numbers});
                return Value(numbers);
            case Kind::namedarray: return Value(NamedArray{type_name, numbers, std::move(d)});
            case Kind::pod: {
                PodArray p = pods;
                p.dims = std::move(d);
                return Value(std::move(p));
            }
        }
        return Value();
    }
};

MemoryMember::MemoryMember(std::shared_ptr<const detail::MemberInfo> info) : info_(std::move(info)) {
    multidim_ = info_->def->type.array == robdef::ArrayKind::multidimarray;
}

const std::string& MemoryMember::name() const noexcept { return info_->def->name; }

void MemoryMember::set_max_transfer_size(std::uint32_t bytes) noexcept {
    std::lock_guard lock(mutex_);
    max_transfer_size_ = bytes;
}

void MemoryMember::on_write(WriteHandler handler) {
    auto h = handler ? std::make_shared<const WriteHandler>(std::move(handler)) : nullptr;
    std::lock_guard lock(mutex_);
    on_write_ = std::move(h);
}

void MemoryMember::clear_handlers() {
    std::shared_ptr<const WriteHandler> h;
    std::lock_guard lock(mutex_);
    h = std::move(on_write_);
}

Result<void> MemoryMember::set_contents(Value contents) {
    // Packing checks the value against the robdef type; unpacking gives the canonical form that
    // client writes also have (field order, views), so block copies can mix both.
    const auto& type = info_->def->type;
    auto packed = detail::pack_member(*info_, contents, type, "data");
    if (!packed) return packed.take_error();
    auto canonical = detail::unpack_member(*info_, *packed, type);
    if (!canonical) return canonical.take_error();
    auto store = std::make_shared<Store>();
    if (auto* a = canonical->get_if<NumericArray>()) {
        store->kind = Store::Kind::numeric;
        store->numbers = *a;
        store->dims = {a->size()};
    } else if (auto* m = canonical->get_if<MultiDimArray>()) {
        store->kind = Store::Kind::numeric;
        store->numbers = m->array;
        store->dims.assign(m->dims.begin(), m->dims.end());
    } else if (auto* na = canonical->get_if<NamedArray>()) {
        auto nt = resolve_named_type(type, info_->types->set(), info_->service_name);
        if (!nt) return nt.take_error();
        auto layout = namedarray_layout(*nt, info_->types->set());
        if (!layout) return layout.take_error();
        store->kind = Store::Kind::namedarray;
        store->type_name = na->type_name;
        store->numbers = na->array;
        store->per_item = layout->elements_per_item;
        if (multidim_)
            store->dims.assign(na->dims.begin(), na->dims.end());
        else
            store->dims = {na->array.size() / store->per_item};
    } else if (auto* p = canonical->get_if<PodArray>()) {
        store->kind = Store::Kind::pod;
        store->type_name = p->type_name;
        store->pods = *p;
        store->pods.dims.clear();
        if (multidim_)
            store->dims.assign(p->dims.begin(), p->dims.end());
        else
            store->dims = {p->count};
    } else {
        return fail(MessageErrorType::DataTypeMismatch, "memory " + name() + ": contents must be an array");
    }
    store->numbers.make_owned();
    std::lock_guard lock(mutex_);
    store_ = std::move(store);
    return {};
}

Value MemoryMember::contents() const {
    std::lock_guard lock(mutex_);
    return store_ ? store_->as_value(multidim_) : Value();
}

std::vector<std::uint64_t> MemoryMember::dimensions() const {
    std::lock_guard lock(mutex_);
    return store_ ? store_->dims : std::vector<std::uint64_t>{};
}

void MemoryMember::handle_request(const SessionRef& session, MessageEntry&& entry, Responder responder) {
    Result<MessageEntry> reply = fail(MessageErrorType::InvalidOperation, "Invalid command");
    switch (entry.entry_type) {
        case MessageEntryType::MemoryRead: reply = read(entry); break;
        case MessageEntryType::MemoryWrite: reply = write(session, entry); break;
        case MessageEntryType::MemoryGetParam: reply = param(entry); break;
        default: reply = fail(MessageErrorType::ProtocolError, "Invalid command"); break;
    }
    if (!reply) {
        responder.fail(reply.error());
        return;
    }
    responder.respond(std::move(*reply));
}

namespace {

/// Position and count of a request, checked against `dims`.
Result<std::pair<std::vector<std::uint64_t>, std::vector<std::uint64_t>>> block_of(const MessageEntry& entry,
                                                                                   const std::vector<std::uint64_t>& dims,
                                                                                   bool multidim) {
    auto pos = read_u64_array(entry, "memorypos");
    if (!pos) return pos.take_error();
    auto count = read_u64_array(entry, "count");
    if (!count) return count.take_error();
    if (!multidim) {
        if (pos->empty() || count->empty()) return fail(out_of_range());
        pos->resize(1);
        count->resize(1);
    }
    if (pos->size() != dims.size() || count->size() != dims.size()) return fail(out_of_range());
    for (std::size_t i = 0; i < dims.size(); ++i)
        if ((*pos)[i] > dims[i] || (*count)[i] > dims[i] - (*pos)[i]) return fail(out_of_range());
    return std::make_pair(std::move(*pos), std::move(*count));
}

}  // namespace

Result<MessageEntry> MemoryMember::read(const MessageEntry& request) {
    if (info_->def->direction() == robdef::MemberDirection::writeonly)
        return fail(MessageErrorType::WriteOnlyMember, "Write only member");
    Value block;
    std::vector<std::uint64_t> pos, count;
    {
        std::lock_guard lock(mutex_);
        if (!store_) return fail(MessageErrorType::ValueNotSet, "memory " + name() + " has no contents");
        auto b = block_of(request, store_->dims, multidim_);
        if (!b) return b.take_error();
        pos = std::move(b->first);
        count = std::move(b->second);
        if (multidim_)
            if (auto d = to_u32_dims(count); !d) return d.take_error();
        block = store_->make_block(count, multidim_);
        for_each_run(store_->dims, pos, count, count, [&](std::size_t m, std::size_t b2, std::size_t n) {
            store_->copy(block, b2, m, n, false);
        });
    }
    auto data = detail::pack_member(*info_, block, info_->def->type, "data");
    if (!data) return data.take_error();
    MessageEntry reply;
    reply.elements.reserve(3);
    reply.elements.push_back(u64_element("memorypos", pos, !multidim_));
    // CORE's multi-dim skeleton sends memorypos as `count` too; we match it byte for byte.
    reply.elements.push_back(u64_element("count", multidim_ ? pos : count, !multidim_));
    reply.elements.push_back(std::move(*data));
    return reply;
}

Result<MessageEntry> MemoryMember::write(const SessionRef& session, const MessageEntry& request) {
    if (info_->def->direction() == robdef::MemberDirection::readonly)
        return fail(MessageErrorType::ReadOnlyMember, "Read only member");
    auto de = detail::require_element(request, "data");
    if (!de) return de.take_error();
    auto data = detail::unpack_member(*info_, **de, info_->def->type);
    if (!data) return data.take_error();
    std::vector<std::uint64_t> pos, count;
    std::shared_ptr<const WriteHandler> on_write;
    {
        std::lock_guard lock(mutex_);
        if (!store_) return fail(MessageErrorType::ValueNotSet, "memory " + name() + " has no contents");
        auto b = block_of(request, store_->dims, multidim_);
        if (!b) return b.take_error();
        pos = std::move(b->first);
        count = std::move(b->second);
        // Dimensions of the data block, which must cover `count`.
        std::vector<std::uint64_t> blk;
        if (auto* a = data->get_if<NumericArray>()) blk = {a->size()};
        if (auto* m = data->get_if<MultiDimArray>()) blk.assign(m->dims.begin(), m->dims.end());
        if (auto* na = data->get_if<NamedArray>())
            blk = multidim_ ? std::vector<std::uint64_t>(na->dims.begin(), na->dims.end())
                            : std::vector<std::uint64_t>{na->array.size() / store_->per_item};
        if (auto* p = data->get_if<PodArray>())
            blk = multidim_ ? std::vector<std::uint64_t>(p->dims.begin(), p->dims.end()) : std::vector<std::uint64_t>{p->count};
        if (blk.size() != count.size()) return fail(out_of_range());
        for (std::size_t i = 0; i < blk.size(); ++i)
            if (blk[i] < count[i]) return fail(out_of_range());
        if (auto* p = data->get_if<PodArray>(); p && p->field_names != store_->pods.field_names)
            return fail(MessageErrorType::DataTypeMismatch, "pod fields differ from the memory's");
        // Copy-on-write: readers holding contents() keep their snapshot.
        for_each_run(store_->dims, pos, blk, count, [&](std::size_t m, std::size_t b2, std::size_t n) {
            store_->copy(*data, b2, m, n, true);
        });
        on_write = on_write_;
    }
    if (on_write) (*on_write)(session, pos, count);
    MessageEntry reply;
    reply.entry_type = MessageEntryType::MemoryReadRet;  // sic: CORE answers MemoryWrite with 1172
    reply.elements.push_back(u64_element("memorypos", pos, !multidim_));
    reply.elements.push_back(u64_element("count", count, !multidim_));
    return reply;
}

Result<MessageEntry> MemoryMember::param(const MessageEntry& request) {
    auto pe = detail::require_element(request, "parameter");
    if (!pe) return pe.take_error();
    if ((*pe)->type != DataTypes::string_t) return fail(MessageErrorType::DataTypeMismatch, "Data type cast error");
    const std::string_view p = read_string(**pe);
    MessageEntry reply;
    std::lock_guard lock(mutex_);
    const std::vector<std::uint64_t> dims = store_ ? store_->dims : std::vector<std::uint64_t>{};
    if (p == "MaxTransferSize") {
        reply.elements.push_back(make_scalar_element<std::uint32_t>("return", max_transfer_size_));
    } else if (!multidim_ && p == "Length") {
        reply.elements.push_back(make_scalar_element<std::uint64_t>("return", dims.empty() ? 0 : dims[0]));
    } else if (multidim_ && p == "DimCount") {
        reply.elements.push_back(make_scalar_element<std::uint64_t>("return", dims.size()));
    } else if (multidim_ && p == "Dimensions") {
        reply.elements.push_back(u64_element("return", dims, false));
    } else {
        return fail(MessageErrorType::InvalidOperation, "Unknown parameter");
    }
    return reply;
}

}  // namespace rr::server
