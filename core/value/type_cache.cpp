#include "core/value/type_cache.hpp"

namespace rr {

Result<const std::vector<PodFieldPlan>*> TypeCache::pod_plans(const NamedType& pod) {
    for (const auto& p : pods_)
        if (p->entry == pod.entry) return &p->plans;
    auto plans = pod_field_plans(pod, lookup_);
    if (!plans) return plans.take_error();
    pods_.push_back(std::make_unique<PodEntry>(PodEntry{pod.entry, std::move(*plans)}));
    return &pods_.back()->plans;
}

Result<NamedArrayLayout> TypeCache::layout(const NamedType& type) {
    for (const auto& l : layouts_)
        if (l.entry == type.entry) return l.layout;
    auto l = namedarray_layout(type, lookup_);
    if (!l) return l.take_error();
    layouts_.push_back({type.entry, *l});
    return *l;
}

}  // namespace rr
