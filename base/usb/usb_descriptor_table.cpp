#include "base/usb/usb_descriptor_table.hpp"

namespace rr::usb {

Result<DescriptorTable> DescriptorTable::build(const DeviceLayout& layout, const DeviceStrings& strings,
                                               const DeviceFunctionConfig& function, bool with_bos,
                                               std::uint8_t vendor_code) {
    if (strings.node_id.is_any()) return fail(MessageErrorType::InvalidArgument, "USB device needs a NodeID");
    DescriptorTable t;
    t.device_ = build_device_descriptor(layout);
    t.configuration_ = build_configuration_descriptor(layout);
    if (with_bos) t.bos_ = build_bos_descriptor(PlatformCapability{layout.interface_number, vendor_code});
    t.langids_ = build_language_ids();
    const std::pair<std::uint8_t, std::string> texts[] = {
        {layout.manufacturer_string, strings.manufacturer}, {layout.product_string, strings.product},
        {layout.serial_string, strings.serial},           {function.node_id_string, strings.node_id.to_string()},
        {function.node_name_string, strings.node_name}};
    for (const auto& [index, text] : texts) {
        if (index == 0) continue;
        if (t.strings_.count(index))
            return fail(MessageErrorType::InvalidArgument, "USB string index " + std::to_string(index) + " used twice");
        auto d = build_string_descriptor(text);
        if (!d) return d.take_error();
        t.strings_.emplace(index, std::move(*d));
    }
    return t;
}

std::vector<std::byte> DescriptorTable::sysfs_descriptors() const {
    std::vector<std::byte> out(device_);
    out.insert(out.end(), configuration_.begin(), configuration_.end());
    return out;
}

Result<std::span<const std::byte>> DescriptorTable::get_descriptor(const SetupPacket& setup) const {
    if (setup.request_type != 0x80 || setup.request != 0x06)
        return fail(MessageErrorType::NotImplementedError, "not a standard GET_DESCRIPTOR request");
    const std::uint8_t type = setup.value >> 8;
    const std::uint8_t index = setup.value & 0xFF;
    switch (type) {
        case 0x01:
            return std::span<const std::byte>(device_);
        case 0x02:
            if (index != 0) break;
            return std::span<const std::byte>(configuration_);
        case kBosDescriptorType:
            if (bos_.empty()) break;
            return std::span<const std::byte>(bos_);
        case kStringDescriptorType: {
            if (index == 0) return std::span<const std::byte>(langids_);
            auto it = strings_.find(index);
            if (it == strings_.end()) break;
            return std::span<const std::byte>(it->second);
        }
        default:
            break;
    }
    return fail(MessageErrorType::ResourceNotFound,
                "no descriptor of type " + std::to_string(type) + " index " + std::to_string(index));
}

}  // namespace rr::usb
