// Robot Raconteur error codes, error names, and the Result<T> type used across core/ and robdef/.
//
// Codes and names: wire.md §5.1 (CORE RobotRaconteurConstants.h enum MessageErrorType, Error.h).
// core/ and robdef/ are built with -fno-exceptions: every fallible call returns Result<T>.
#pragma once

#include <cstdint>
#include <cstdlib>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <variant>

namespace rr {

/// MessageErrorType: the uint16 `Error` field of a MessageEntry (wire.md §5.1). 0 = no error.
enum class MessageErrorType : std::uint16_t {
    None = 0,
    ConnectionError = 1,
    ProtocolError = 2,
    ServiceNotFound = 3,
    ObjectNotFound = 4,
    InvalidEndpoint = 5,
    EndpointCommunicationFatalError = 6,
    NodeNotFound = 7,
    ServiceError = 8,
    MemberNotFound = 9,
    MemberFormatMismatch = 10,
    DataTypeMismatch = 11,
    DataTypeError = 12,
    DataSerializationError = 13,
    MessageEntryNotFound = 14,
    MessageElementNotFound = 15,
    UnknownError = 16,
    InvalidOperation = 17,
    InvalidArgument = 18,
    OperationFailed = 19,
    NullValue = 20,
    InternalError = 21,
    SystemResourcePermissionDenied = 22,
    OutOfSystemResource = 23,
    SystemResourceError = 24,
    ResourceNotFound = 25,
    IOError = 26,
    BufferLimitViolation = 27,
    ServiceDefinitionError = 28,
    OutOfRange = 29,
    KeyNotFound = 30,
    InvalidConfiguration = 31,
    InvalidState = 32,
    RemoteError = 100,
    RequestTimeout = 101,
    ReadOnlyMember = 102,
    WriteOnlyMember = 103,
    NotImplementedError = 104,
    MemberBusy = 105,
    ValueNotSet = 106,
    AbortOperation = 107,
    OperationAborted = 108,
    StopIteration = 109,
    OperationTimeout = 110,
    OperationCancelled = 111,
    AuthenticationError = 150,
    ObjectLockedError = 151,
    PermissionDenied = 152,
};

/// Standard error name for a code, e.g. "RobotRaconteur.MemberNotFound".
/// Returns "" for None, RemoteError and UnknownError (their name travels in the `errorname` element)
/// and for codes not in the table.
std::string_view error_name(MessageErrorType type) noexcept;

/// Code for a standard error name; RemoteError for any name not in the table (user exceptions such as
/// "experimental.arm.MotorFault"). Also maps CORE's non-canonical "…ServiceNotFoundException" and
/// "…ObjectNotFoundException" names (wire.md §5.1).
MessageErrorType error_type_from_name(std::string_view name) noexcept;

struct MessageElement;  // base/message/message.hpp

/// An RR error as carried in an error entry (wire.md §5.2): code, `errorname`, `errorstring`,
/// optional `errorsubname` and `errorparam`. User error names pass through unchanged.
struct RRError {
    MessageErrorType type = MessageErrorType::UnknownError;
    std::string name;     ///< errorname; filled from error_name(type) by make_error when empty
    std::string message;  ///< errorstring: human-readable
    std::string sub_name; ///< errorsubname, usually empty
    /// errorparam: a varvalue element (any name; sent as `errorparam`), usually null. Immutable and
    /// shared by copies; equality compares the pointer.
    std::shared_ptr<const MessageElement> param = nullptr;

    friend bool operator==(const RRError&, const RRError&) = default;
};

/// Builds an RRError with the standard name for `type`.
RRError make_error(MessageErrorType type, std::string message);

/// An RRError on the heap: a Result's error alternative is then one pointer wide, not the three
/// strings of an RRError, so a Result is about the size of its value (every decoder step returns a
/// Result; errors are the rare path).
/// Copying copies the error. A moved-from box is empty: after take_error() a Result may only be
/// destroyed or assigned.
class ErrorBox {
public:
    explicit ErrorBox(RRError error) : p_(std::make_unique<RRError>(std::move(error))) {}
    ErrorBox(const ErrorBox& o) : p_(o.p_ ? std::make_unique<RRError>(*o.p_) : nullptr) {}
    ErrorBox(ErrorBox&&) noexcept = default;
    ErrorBox& operator=(ErrorBox o) noexcept {
        p_ = std::move(o.p_);
        return *this;
    }

    RRError& operator*() const noexcept { return *p_; }
    RRError* operator->() const noexcept { return p_.get(); }

private:
    std::unique_ptr<RRError> p_;
};

/// Wraps an RRError so that `return fail(...)` converts into any Result<T>.
struct Unexpected {
    explicit Unexpected(RRError e) : error(std::move(e)) {}
    explicit Unexpected(ErrorBox e) noexcept : error(std::move(e)) {}
    ErrorBox error;
};

inline Unexpected fail(MessageErrorType type, std::string message) {
    return Unexpected{make_error(type, std::move(message))};
}
inline Unexpected fail(RRError error) { return Unexpected{std::move(error)}; }

/// Result<T>: a value or an RRError (a small expected<T, RRError> until C++23); the error is boxed
/// (ErrorBox), so a Result is the size of T plus a tag.
/// Calling value() on an error, or error() on a value, is a programming error and aborts.
template <class T>
class [[nodiscard]] Result {
public:
    // Two overloads, not one by value: `return value;` then moves the value once, not twice.
    Result(const T& value) : v_(std::in_place_index<0>, value) {}
    Result(T&& value) : v_(std::in_place_index<0>, std::move(value)) {}
    Result(Unexpected u) : v_(std::in_place_index<1>, std::move(u.error)) {}

    bool ok() const noexcept { return v_.index() == 0; }
    explicit operator bool() const noexcept { return ok(); }

    T& value() & { check(true); return std::get<0>(v_); }
    const T& value() const& { check(true); return std::get<0>(v_); }
    T&& value() && { check(true); return std::get<0>(std::move(v_)); }
    T& operator*() & { return value(); }
    const T& operator*() const& { return value(); }
    T&& operator*() && { return std::move(*this).value(); }
    T* operator->() { return &value(); }
    const T* operator->() const { return &value(); }

    const RRError& error() const& { check(false); return *std::get<1>(v_); }
    RRError&& error() && { check(false); return std::move(*std::get<1>(v_)); }
    /// Converts the error into an Unexpected for propagation: `if (!r) return r.take_error();`
    Unexpected take_error() { check(false); return Unexpected{std::get<1>(std::move(v_))}; }

private:
    void check(bool want_value) const {
        if (ok() != want_value) std::abort();
    }
    std::variant<T, ErrorBox> v_;
};

template <>
class [[nodiscard]] Result<void> {
public:
    Result() = default;
    Result(Unexpected u) : err_(std::move(u.error)) {}

    bool ok() const noexcept { return !err_; }
    explicit operator bool() const noexcept { return ok(); }
    void value() const { if (err_) std::abort(); }

    const RRError& error() const& { if (!err_) std::abort(); return **err_; }
    Unexpected take_error() { if (!err_) std::abort(); return Unexpected{std::move(*err_)}; }

private:
    std::optional<ErrorBox> err_;
};

}  // namespace rr
