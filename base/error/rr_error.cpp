#include "base/error/rr_error.hpp"

#include <array>

namespace rr {
namespace {

struct NameEntry {
    MessageErrorType type;
    std::string_view name;
};

constexpr std::array kNames{
    NameEntry{MessageErrorType::ConnectionError, "RobotRaconteur.ConnectionError"},
    NameEntry{MessageErrorType::ProtocolError, "RobotRaconteur.ProtocolError"},
    NameEntry{MessageErrorType::ServiceNotFound, "RobotRaconteur.ServiceNotFound"},
    NameEntry{MessageErrorType::ObjectNotFound, "RobotRaconteur.ObjectNotFound"},
    NameEntry{MessageErrorType::InvalidEndpoint, "RobotRaconteur.InvalidEndpoint"},
    NameEntry{MessageErrorType::EndpointCommunicationFatalError,
              "RobotRaconteur.EndpointCommunicationFatalError"},
    NameEntry{MessageErrorType::NodeNotFound, "RobotRaconteur.NodeNotFound"},
    NameEntry{MessageErrorType::ServiceError, "RobotRaconteur.ServiceError"},
    NameEntry{MessageErrorType::MemberNotFound, "RobotRaconteur.MemberNotFound"},
    NameEntry{MessageErrorType::MemberFormatMismatch, "RobotRaconteur.MemberFormatMismatch"},
    NameEntry{MessageErrorType::DataTypeMismatch, "RobotRaconteur.DataTypeMismatch"},
    NameEntry{MessageErrorType::DataTypeError, "RobotRaconteur.DataTypeError"},
    NameEntry{MessageErrorType::DataSerializationError, "RobotRaconteur.DataSerializationError"},
    NameEntry{MessageErrorType::MessageEntryNotFound, "RobotRaconteur.MessageEntryNotFound"},
    NameEntry{MessageErrorType::MessageElementNotFound, "RobotRaconteur.MessageElementNotFound"},
    NameEntry{MessageErrorType::InvalidOperation, "RobotRaconteur.InvalidOperation"},
    NameEntry{MessageErrorType::InvalidArgument, "RobotRaconteur.InvalidArgument"},
    NameEntry{MessageErrorType::OperationFailed, "RobotRaconteur.OperationFailed"},
    NameEntry{MessageErrorType::NullValue, "RobotRaconteur.NullValue"},
    NameEntry{MessageErrorType::InternalError, "RobotRaconteur.InternalError"},
    NameEntry{MessageErrorType::SystemResourcePermissionDenied,
              "RobotRaconteur.SystemResourcePermissionDenied"},
    NameEntry{MessageErrorType::OutOfSystemResource, "RobotRaconteur.OutOfSystemResource"},
    NameEntry{MessageErrorType::SystemResourceError, "RobotRaconteur.SystemResourceError"},
    NameEntry{MessageErrorType::ResourceNotFound, "RobotRaconteur.ResourceNotFound"},
    NameEntry{MessageErrorType::IOError, "RobotRaconteur.IOError"},
    NameEntry{MessageErrorType::BufferLimitViolation, "RobotRaconteur.BufferLimitViolation"},
    NameEntry{MessageErrorType::ServiceDefinitionError, "RobotRaconteur.ServiceDefinitionError"},
    NameEntry{MessageErrorType::OutOfRange, "RobotRaconteur.OutOfRange"},
    NameEntry{MessageErrorType::KeyNotFound, "RobotRaconteur.KeyNotFound"},
    NameEntry{MessageErrorType::InvalidConfiguration, "RobotRaconteur.InvalidConfiguration"},
    NameEntry{MessageErrorType::InvalidState, "RobotRaconteur.InvalidState"},
    NameEntry{MessageErrorType::RequestTimeout, "RobotRaconteur.RequestTimeout"},
    NameEntry{MessageErrorType::ReadOnlyMember, "RobotRaconteur.ReadOnlyMember"},
    NameEntry{MessageErrorType::WriteOnlyMember, "RobotRaconteur.WriteOnlyMember"},
    NameEntry{MessageErrorType::NotImplementedError, "RobotRaconteur.NotImplementedError"},
    NameEntry{MessageErrorType::MemberBusy, "RobotRaconteur.MemberBusy"},
    NameEntry{MessageErrorType::ValueNotSet, "RobotRaconteur.ValueNotSet"},
    NameEntry{MessageErrorType::AbortOperation, "RobotRaconteur.AbortOperation"},
    NameEntry{MessageErrorType::OperationAborted, "RobotRaconteur.OperationAborted"},
    NameEntry{MessageErrorType::StopIteration, "RobotRaconteur.StopIteration"},
    NameEntry{MessageErrorType::OperationTimeout, "RobotRaconteur.OperationTimeout"},
    NameEntry{MessageErrorType::OperationCancelled, "RobotRaconteur.OperationCancelled"},
    NameEntry{MessageErrorType::AuthenticationError, "RobotRaconteur.AuthenticationError"},
    NameEntry{MessageErrorType::ObjectLockedError, "RobotRaconteur.ObjectLockedError"},
    NameEntry{MessageErrorType::PermissionDenied, "RobotRaconteur.PermissionDenied"},
};

}  // namespace

std::string_view error_name(MessageErrorType type) noexcept {
    for (const auto& e : kNames)
        if (e.type == type) return e.name;
    return {};
}

MessageErrorType error_type_from_name(std::string_view name) noexcept {
    for (const auto& e : kNames)
        if (e.name == name) return e.type;
    // Names CORE sends on some special-request error paths (wire.md §5.1).
    if (name == "RobotRaconteur.ServiceNotFoundException") return MessageErrorType::ServiceNotFound;
    if (name == "RobotRaconteur.ObjectNotFoundException") return MessageErrorType::ObjectNotFound;
    return MessageErrorType::RemoteError;
}

RRError make_error(MessageErrorType type, std::string message) {
    RRError e;
    e.type = type;
    e.name = std::string(error_name(type));
    e.message = std::move(message);
    return e;
}

}  // namespace rr
