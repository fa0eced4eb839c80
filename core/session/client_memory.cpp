// ClientContext: memories (wire.md §6.7; CORE MemoryMember.cpp, MemoryMember.h).
//
// MemoryGetParam `parameter` ∈ {Length, DimCount, Dimensions, MaxTransferSize} → `return`.
// MemoryRead {memorypos, count} → {memorypos, count, data}; MemoryWrite {memorypos, count, data} (CORE
// answers it with EntryType MemoryReadRet; replies are matched by RequestID only). Array memories send
// uint64 scalars, multi-dim memories uint64 arrays. `data` is packed as the memory's type: `T[]`
// (numeric array, pod array 110, namedarray array 115) or `T[*]` (117, 111, 116, column-major).
//
// Transfers larger than min(our, the service's MaxTransferSize) bytes are split into blocks and sent one
// after the other; multi-dim blocks keep the leading (fastest) dimensions whole, as far as they fit.
#include <algorithm>

#include "core/session/client_context.hpp"
#include "core/session/client_state.hpp"
#include "core/session/elements.hpp"
#include "core/value/element_layout.hpp"
#include "core/value/named_type.hpp"

namespace rr {

using robdef::ArrayKind;
using robdef::MemberDirection;
using robdef::MemberKind;
using robdef::NamedTypeKind;

struct ClientContext::MemoryOp {
    struct Block {
        std::vector<std::uint64_t> origin;  ///< within the requested block
        std::vector<std::uint64_t> shape;
    };
    std::string path, member;
    std::shared_ptr<const MemoryCaps> caps;
    bool write = false;
    std::vector<std::uint64_t> pos, count;  ///< of the whole request (one entry for array memories)
    std::vector<Block> blocks;
    std::size_t next = 0;
    Value data;                ///< write: what is written
    std::vector<Value> parts;  ///< read: the answer of each block
    Completion<Value> read_done;
    Completion<void> write_done;
};

namespace {

// Packed bytes of one pod item (bounded fields count at their maximum), for chunking only.
Result<std::size_t> pod_bytes(const NamedType& pod, const robdef::TypeLookup& lookup, int depth = 0) {
    if (depth > 16) return fail(MessageErrorType::DataTypeError, "pod nesting too deep");
    auto plans = pod_field_plans(pod, lookup);
    if (!plans) return plans.take_error();
    std::size_t total = 0;
    for (const auto& p : *plans) {
        std::size_t n = p.wire_type.array == ArrayKind::none ? 1 : std::max<std::size_t>(1, array_length_rule(p.wire_type).length);
        std::size_t item = 0;
        if (p.named.kind == NamedTypeKind::pod) {
            auto b = pod_bytes(p.named, lookup, depth + 1);
            if (!b) return b.take_error();
            item = *b;
        } else if (p.named.kind == NamedTypeKind::namedarray) {
            auto l = namedarray_layout(p.named, lookup);
            if (!l) return l.take_error();
            item = l->elements_per_item * data_type_size(l->element_type);
        } else {
            item = data_type_size(p.wire_type.base);
        }
        total += n * item;
    }
    return std::max<std::size_t>(total, 1);
}

std::uint64_t product(const std::vector<std::uint64_t>& v) {
    std::uint64_t p = 1;
    for (auto x : v) p *= x;
    return p;
}

// Blocks of at most `max_items` items covering `count` (column-major: dimension 0 varies fastest).
std::vector<ClientContext::MemoryOp::Block> plan_blocks(const std::vector<std::uint64_t>& count, std::uint64_t max_items) {
    using Block = ClientContext::MemoryOp::Block;
    const std::size_t n = count.size();
    if (product(count) <= max_items) return {Block{std::vector<std::uint64_t>(n, 0), count}};
    // Leading dimensions that fit whole, then a slice of the next one, then single steps.
    std::size_t k = 0;
    std::uint64_t p = 1;
    while (k < n && p * count[k] <= max_items) p *= count[k++];
    std::vector<std::uint64_t> shape(n, 1);
    for (std::size_t i = 0; i < k; ++i) shape[i] = count[i];
    shape[k] = std::max<std::uint64_t>(1, max_items / p);
    std::vector<Block> blocks;
    std::vector<std::uint64_t> origin(n, 0);
    for (;;) {
        Block b{origin, shape};
        b.shape[k] = std::min(shape[k], count[k] - origin[k]);
        blocks.push_back(std::move(b));
        // Next origin: step dimension k by its slice, then the outer dimensions one by one.
        std::size_t d = k;
        origin[d] += shape[d];
        while (origin[d] >= count[d]) {
            origin[d] = 0;
            if (++d == n) return blocks;
            origin[d] += 1;
        }
    }
}

// Calls f(block_linear, full_linear) for every item of the block at `origin` of shape `shape` inside an
// array of shape `full` (both linear indices column-major).
template <class F>
void for_each_block_item(const std::vector<std::uint64_t>& full, const std::vector<std::uint64_t>& origin,
                         const std::vector<std::uint64_t>& shape, F&& f) {
    const std::size_t n = full.size();
    const std::uint64_t total = product(shape);
    if (total == 0) return;
    std::vector<std::uint64_t> stride(n, 1);
    for (std::size_t i = 1; i < n; ++i) stride[i] = stride[i - 1] * full[i - 1];
    std::vector<std::uint64_t> idx(n, 0);
    for (std::uint64_t t = 0; t < total; ++t) {
        std::uint64_t lin = 0;
        for (std::size_t i = 0; i < n; ++i) lin += (origin[i] + idx[i]) * stride[i];
        f(static_cast<std::size_t>(t), static_cast<std::size_t>(lin));
        for (std::size_t i = 0; i < n && ++idx[i] == shape[i]; ++i) idx[i] = 0;
    }
}

// The items of a memory value: bytes of numeric / namedarray items, or the pod items.
struct ItemView {
    std::size_t count = 0;
    SharedBytes bytes;
    std::size_t item_bytes = 0;
    const PodArray* pod = nullptr;
};

Result<ItemView> items_of(const Value& v, const ClientContext::MemoryCaps& caps) {
    ItemView iv;
    if (caps.pod) {
        iv.pod = v.get_if<PodArray>();
        if (!iv.pod) return fail(MessageErrorType::DataTypeMismatch, "memory data must be a pod array of " + caps.named_type);
        iv.count = iv.pod->count;
        return iv;
    }
    const NumericArray* a = nullptr;
    if (caps.namedarray) {
        if (const auto* n = v.get_if<NamedArray>()) a = &n->array;
    } else if (const auto* m = v.get_if<MultiDimArray>()) {
        a = &m->array;
    } else {
        a = v.get_if<NumericArray>();
    }
    if (!a || a->type() != caps.element_type)
        return fail(MessageErrorType::DataTypeMismatch, "memory data does not match the memory type");
    iv.item_bytes = data_type_size(caps.element_type) * caps.elements_per_item;
    if (a->size() % caps.elements_per_item != 0)
        return fail(MessageErrorType::DataTypeError, "namedarray data is not a whole number of items");
    iv.count = a->size() / caps.elements_per_item;
    iv.bytes = a->to_bytes();
    return iv;
}

// Builds a memory value of `count` items from items of other values.
class ItemSink {
public:
    ItemSink(const ClientContext::MemoryCaps& caps, std::size_t count, const PodArray* proto) : caps_(caps) {
        if (caps.pod) {
            pod_ = PodArray(proto ? proto->type_name : caps.named_type, proto ? proto->field_names : std::vector<std::string>{});
            pod_.values.resize(count * pod_.field_names.size());
            pod_.count = count;
        } else {
            item_bytes_ = data_type_size(caps.element_type) * caps.elements_per_item;
            bytes_.resize(count * item_bytes_);
        }
    }
    void copy(const ItemView& src, std::size_t from, std::size_t to) {
        if (caps_.pod) {
            const std::size_t nf = pod_.field_names.size();
            for (std::size_t j = 0; j < nf; ++j) {
                const Value* f = src.pod->field(from, pod_.field_names[j]);
                if (f) pod_.values[to * nf + j] = *f;
            }
        } else {
            std::copy_n(src.bytes.data() + from * item_bytes_, item_bytes_, bytes_.data() + to * item_bytes_);
        }
    }
    Result<Value> finish(const std::vector<std::uint64_t>& shape, bool multidim) {
        std::vector<std::uint32_t> dims;
        if (multidim)
            for (auto d : shape) dims.push_back(static_cast<std::uint32_t>(d));
        if (caps_.pod) {
            pod_.dims = std::move(dims);
            return Value(std::move(pod_));
        }
        auto a = NumericArray::wrap(caps_.element_type, SharedBytes::adopt(std::move(bytes_)));
        if (!a) return a.take_error();
        if (caps_.namedarray) return Value(NamedArray{caps_.named_type, std::move(*a), std::move(dims)});
        if (multidim) return Value(MultiDimArray{std::move(dims), std::move(*a)});
        return Value(std::move(*a));
    }

private:
    const ClientContext::MemoryCaps& caps_;
    std::size_t item_bytes_ = 0;
    std::vector<std::byte> bytes_;
    PodArray pod_;
};

// The dims of a multi-dim memory value (the shape of a write).
Result<std::vector<std::uint64_t>> value_dims(const Value& v) {
    const std::vector<std::uint32_t>* d = nullptr;
    if (const auto* m = v.get_if<MultiDimArray>()) d = &m->dims;
    else if (const auto* p = v.get_if<PodArray>()) d = &p->dims;
    else if (const auto* n = v.get_if<NamedArray>()) d = &n->dims;
    if (!d || d->empty()) return fail(MessageErrorType::DataTypeMismatch, "multi-dim memory data needs dims");
    return std::vector<std::uint64_t>(d->begin(), d->end());
}

MessageElement uint64s(std::string name, const std::vector<std::uint64_t>& v) {
    return make_array_element<std::uint64_t>(std::move(name), std::span<const std::uint64_t>(v));
}

}  // namespace

void ClientContext::memory_param(std::string_view path, std::string_view member, std::string_view param, MonoTime now,
                                 Completion<MessageElement> done) {
    auto e = member_entry(MessageEntryType::MemoryGetParam, path, member);
    e.elements.push_back(make_string_element("parameter", param));
    send_request(std::move(e), now, [done = std::move(done)](Result<MessageEntry> r) {
        r = reply_result(std::move(r));
        if (!r) return done(r.take_error());
        const auto* ret = r->find("return");
        if (!ret) return done(fail(MessageErrorType::MessageElementNotFound, "MemoryGetParamRet without return"));
        done(*ret);
    });
}

void ClientContext::memory_caps(std::string_view path, std::string_view member, bool multidim, MonoTime now,
                                Completion<std::shared_ptr<const MemoryCaps>> done) {
    const ObjectState* obj = nullptr;
    auto m = find_member(path, member, MemberKind::memory, &obj);
    if (!m) return done(m.take_error());
    const robdef::TypeDefinition& t = (*m)->type;
    const bool is_md = t.array == ArrayKind::multidimarray;
    if (is_md != multidim)
        return done(fail(MessageErrorType::InvalidOperation,
                         "memory \"" + std::string(member) +
                             (is_md ? "\" is multi-dim: use position and count vectors" : "\" is not multi-dim")));
    auto key = member_key(path, member);
    if (auto it = memory_caps_.find(key); it != memory_caps_.end()) return done(it->second);

    auto caps = std::make_shared<MemoryCaps>();
    caps->type = t;
    caps->context_service = obj->service->name;
    caps->multidim = is_md;
    caps->readable = (*m)->direction() != MemberDirection::writeonly;
    caps->writable = (*m)->direction() != MemberDirection::readonly;
    if (is_numeric(t.base)) {
        caps->element_type = t.base;
        caps->item_bytes = data_type_size(t.base);
    } else if (t.base == DataTypes::namedtype_t) {
        auto nt = resolve_named_type(t, defs_, caps->context_service);
        if (!nt) return done(nt.take_error());
        caps->named_type = nt->qualified_name;
        if (nt->kind == NamedTypeKind::pod) {
            caps->pod = true;
            auto b = pod_bytes(*nt, defs_);
            if (!b) return done(b.take_error());
            caps->item_bytes = *b;
        } else if (nt->kind == NamedTypeKind::namedarray) {
            auto l = namedarray_layout(*nt, defs_);
            if (!l) return done(l.take_error());
            caps->namedarray = true;
            caps->element_type = l->element_type;
            caps->elements_per_item = l->elements_per_item;
            caps->item_bytes = l->elements_per_item * data_type_size(l->element_type);
        } else {
            return done(fail(MessageErrorType::DataTypeError, "memory of " + nt->qualified_name + " is not supported"));
        }
    } else {
        return done(fail(MessageErrorType::DataTypeError, "memory type " + t.to_string() + " is not supported"));
    }
    memory_param(path, member, "MaxTransferSize", now,
                 [this, caps, key, done = std::move(done)](Result<MessageElement> r) {
                     if (!r) return done(r.take_error());
                     std::uint32_t remote = 0;
                     if (!read_scalar(*r, remote))
                         return done(fail(MessageErrorType::DataTypeMismatch, "MaxTransferSize is not a uint32"));
                     std::uint32_t max = config_.memory_max_transfer_size;
                     if (remote != 0 && remote < max) max = remote;
                     caps->max_items = std::max<std::uint64_t>(1, max / caps->item_bytes);
                     memory_caps_[key] = caps;
                     done(std::shared_ptr<const MemoryCaps>(caps));
                 });
}

namespace {

// memory_param's answer for a uint64 parameter (Length, DimCount) as that number.
auto uint64_param(std::string name, Completion<std::uint64_t> done) {
    return [name = std::move(name), done = std::move(done)](Result<MessageElement> r) {
        if (!r) return done(r.take_error());
        std::uint64_t v = 0;
        if (!read_scalar(*r, v)) return done(fail(MessageErrorType::DataTypeMismatch, name + " is not a uint64"));
        done(v);
    };
}

}  // namespace

void ClientContext::memory_length(std::string_view path, std::string_view member, MonoTime now,
                                  Completion<std::uint64_t> done) {
    auto m = find_member(path, member, MemberKind::memory);
    if (!m) return done(m.take_error());
    memory_param(path, member, "Length", now, uint64_param("Length", std::move(done)));
}

void ClientContext::memory_dim_count(std::string_view path, std::string_view member, MonoTime now,
                                     Completion<std::uint64_t> done) {
    auto m = find_member(path, member, MemberKind::memory);
    if (!m) return done(m.take_error());
    memory_param(path, member, "DimCount", now, uint64_param("DimCount", std::move(done)));
}

void ClientContext::memory_dimensions(std::string_view path, std::string_view member, MonoTime now,
                                      Completion<std::vector<std::uint64_t>> done) {
    auto m = find_member(path, member, MemberKind::memory);
    if (!m) return done(m.take_error());
    memory_param(path, member, "Dimensions", now, [done = std::move(done)](Result<MessageElement> r) {
        if (!r) return done(r.take_error());
        if (r->type != DataTypes::uint64_t)
            return done(fail(MessageErrorType::DataTypeMismatch, "Dimensions is not a uint64 array"));
        done(read_array<std::uint64_t>(*r));
    });
}

void ClientContext::memory_read(std::string_view path, std::string_view member, std::uint64_t pos,
                                std::uint64_t count, MonoTime now, Completion<Value> done) {
    memory_caps(path, member, false, now,
                [this, path = std::string(path), member = std::string(member), pos, count,
                 done = std::move(done)](Result<std::shared_ptr<const MemoryCaps>> caps) mutable {
                    if (!caps) return done(caps.take_error());
                    if (!(*caps)->readable)
                        return done(fail(MessageErrorType::WriteOnlyMember, "memory \"" + member + "\" is write-only"));
                    auto op = std::make_shared<MemoryOp>();
                    op->path = std::move(path);
                    op->member = std::move(member);
                    op->caps = std::move(*caps);
                    op->pos = {pos};
                    op->count = {count};
                    op->blocks = plan_blocks(op->count, op->caps->max_items);
                    op->read_done = std::move(done);
                    memory_step(std::move(op), now_);
                });
}

void ClientContext::memory_read(std::string_view path, std::string_view member, std::vector<std::uint64_t> pos,
                                std::vector<std::uint64_t> count, MonoTime now, Completion<Value> done) {
    if (pos.size() != count.size() || pos.empty())
        return done(fail(MessageErrorType::InvalidArgument, "memory position and count need the same number of dims (≥ 1)"));
    for (auto c : count)
        if (c > UINT32_MAX) return done(fail(MessageErrorType::OutOfRange, "memory count over 2^32-1 in one dim"));
    memory_caps(path, member, true, now,
                [this, path = std::string(path), member = std::string(member), pos = std::move(pos),
                 count = std::move(count), done = std::move(done)](Result<std::shared_ptr<const MemoryCaps>> caps) mutable {
                    if (!caps) return done(caps.take_error());
                    if (!(*caps)->readable)
                        return done(fail(MessageErrorType::WriteOnlyMember, "memory \"" + member + "\" is write-only"));
                    auto op = std::make_shared<MemoryOp>();
                    op->path = std::move(path);
                    op->member = std::move(member);
                    op->caps = std::move(*caps);
                    op->pos = std::move(pos);
                    op->count = std::move(count);
                    op->blocks = plan_blocks(op->count, op->caps->max_items);
                    op->read_done = std::move(done);
                    memory_step(std::move(op), now_);
                });
}

void ClientContext::memory_write(std::string_view path, std::string_view member, std::uint64_t pos, Value data,
                                 MonoTime now, Completion<void> done) {
    memory_caps(path, member, false, now,
                [this, path = std::string(path), member = std::string(member), pos, data = std::move(data),
                 done = std::move(done)](Result<std::shared_ptr<const MemoryCaps>> caps) mutable {
                    if (!caps) return done(caps.take_error());
                    if (!(*caps)->writable)
                        return done(fail(MessageErrorType::ReadOnlyMember, "memory \"" + member + "\" is read-only"));
                    auto items = items_of(data, **caps);
                    if (!items) return done(items.take_error());
                    auto op = std::make_shared<MemoryOp>();
                    op->path = std::move(path);
                    op->member = std::move(member);
                    op->caps = std::move(*caps);
                    op->write = true;
                    op->pos = {pos};
                    op->count = {items->count};
                    op->blocks = plan_blocks(op->count, op->caps->max_items);
                    op->data = std::move(data);
                    op->write_done = std::move(done);
                    memory_step(std::move(op), now_);
                });
}

void ClientContext::memory_write(std::string_view path, std::string_view member, std::vector<std::uint64_t> pos,
                                 Value data, MonoTime now, Completion<void> done) {
    auto dims = value_dims(data);
    if (!dims) return done(dims.take_error());
    if (pos.size() != dims->size())
        return done(fail(MessageErrorType::InvalidArgument, "memory position has " + std::to_string(pos.size()) +
                                                                " dims, data " + std::to_string(dims->size())));
    memory_caps(path, member, true, now,
                [this, path = std::string(path), member = std::string(member), pos = std::move(pos),
                 dims = std::move(*dims), data = std::move(data),
                 done = std::move(done)](Result<std::shared_ptr<const MemoryCaps>> caps) mutable {
                    if (!caps) return done(caps.take_error());
                    if (!(*caps)->writable)
                        return done(fail(MessageErrorType::ReadOnlyMember, "memory \"" + member + "\" is read-only"));
                    auto items = items_of(data, **caps);
                    if (!items) return done(items.take_error());
                    if (items->count != product(dims))
                        return done(fail(MessageErrorType::DataTypeError, "memory data dims do not match its items"));
                    auto op = std::make_shared<MemoryOp>();
                    op->path = std::move(path);
                    op->member = std::move(member);
                    op->caps = std::move(*caps);
                    op->write = true;
                    op->pos = std::move(pos);
                    op->count = std::move(dims);
                    op->blocks = plan_blocks(op->count, op->caps->max_items);
                    op->data = std::move(data);
                    op->write_done = std::move(done);
                    memory_step(std::move(op), now_);
                });
}

void ClientContext::memory_step(std::shared_ptr<MemoryOp> op, MonoTime now) {
    const MemoryCaps& caps = *op->caps;
    auto finish_error = [&](RRError err) {
        if (op->write) op->write_done(fail(std::move(err)));
        else op->read_done(fail(std::move(err)));
    };
    if (op->next == op->blocks.size()) {
        if (op->write) return op->write_done({});
        if (op->parts.size() == 1) return op->read_done(std::move(op->parts.front()));  // zero-copy
        const PodArray* proto = caps.pod ? op->parts.front().get_if<PodArray>() : nullptr;
        ItemSink sink(caps, static_cast<std::size_t>(product(op->count)), proto);
        for (std::size_t i = 0; i < op->blocks.size(); ++i) {
            auto src = items_of(op->parts[i], caps);
            if (!src) return finish_error(src.error());
            for_each_block_item(op->count, op->blocks[i].origin, op->blocks[i].shape,
                                [&](std::size_t t, std::size_t lin) { sink.copy(*src, t, lin); });
        }
        auto v = sink.finish(op->count, caps.multidim);
        if (!v) return finish_error(v.error());
        return op->read_done(std::move(*v));
    }
    const MemoryOp::Block& b = op->blocks[op->next];
    std::vector<std::uint64_t> mem_pos(op->pos.size());
    for (std::size_t i = 0; i < mem_pos.size(); ++i) {
        mem_pos[i] = op->pos[i] + b.origin[i];
        if (mem_pos[i] < op->pos[i]) return finish_error(make_error(MessageErrorType::OutOfRange, "memory position overflows"));
    }
    auto e = member_entry(op->write ? MessageEntryType::MemoryWrite : MessageEntryType::MemoryRead, op->path, op->member);
    if (caps.multidim) {
        e.elements.push_back(uint64s("memorypos", mem_pos));
        e.elements.push_back(uint64s("count", b.shape));
    } else {
        e.elements.push_back(make_scalar_element<std::uint64_t>("memorypos", mem_pos[0]));
        e.elements.push_back(make_scalar_element<std::uint64_t>("count", b.shape[0]));
    }
    if (op->write) {
        Result<MessageElement> el = fail(MessageErrorType::InternalError, "");
        if (op->blocks.size() == 1) {
            el = pack(op->data, caps.type, "data", caps.context_service);
        } else {
            auto src = items_of(op->data, caps);
            if (!src) return finish_error(src.error());
            ItemSink sink(caps, static_cast<std::size_t>(product(b.shape)), src->pod);
            for_each_block_item(op->count, b.origin, b.shape, [&](std::size_t t, std::size_t lin) { sink.copy(*src, lin, t); });
            auto slice = sink.finish(b.shape, caps.multidim);
            if (!slice) return finish_error(slice.error());
            el = pack(*slice, caps.type, "data", caps.context_service);
        }
        if (!el) return finish_error(el.error());
        e.elements.push_back(std::move(*el));
    }
    send_request(std::move(e), now, [this, op](Result<MessageEntry> r) {
        r = reply_result(std::move(r));
        auto finish = [&](RRError err) {
            if (op->write) op->write_done(fail(std::move(err)));
            else op->read_done(fail(std::move(err)));
        };
        if (!r) return finish(r.error());
        if (!op->write) {
            const auto* d = r->find("data");
            if (!d) return finish(make_error(MessageErrorType::MessageElementNotFound, "MemoryReadRet without data"));
            auto v = unpack(*d, op->caps->type, op->caps->context_service);
            if (!v) return finish(v.error());
            auto items = items_of(*v, *op->caps);
            if (!items) return finish(items.error());
            if (items->count != product(op->blocks[op->next].shape))
                return finish(make_error(MessageErrorType::ProtocolError, "MemoryReadRet holds " +
                                                                              std::to_string(items->count) + " items, asked for " +
                                                                              std::to_string(product(op->blocks[op->next].shape))));
            op->parts.push_back(std::move(*v));
        }
        ++op->next;
        memory_step(op, now_);
    });
}

}  // namespace rr
