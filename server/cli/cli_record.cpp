#include "server/cli/cli_record.hpp"

#include <chrono>
#include <thread>

#include "base/names/connection_url.hpp"
#include "server/cli/cli_commands.hpp"
#include "server/cli/cli_target.hpp"
#include "server/gateway/device_mirror.hpp"
#include "server/gateway/json_api.hpp"
#include "server/node/node.hpp"
#include "server/record/recording.hpp"
#include "server/record/replay_device.hpp"
#include "server/transport/tcp_listener.hpp"

namespace rr::cli {

namespace {

using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;

ExitCode fail_with(std::ostream& err, ExitCode code, const RRError& e) {
    print_error(err, e);
    return code;
}

bool stop_or_elapsed(const std::atomic<bool>& stop, Clock::time_point deadline) {
    return stop.load() || Clock::now() >= deadline;
}

}  // namespace

ExitCode run_record(const CommandLine& cl, std::ostream& out, std::ostream& err, const std::atomic<bool>& stop) {
    auto parsed = parse_connection_url(cl.url);
    if (!parsed) return fail_with(err, ExitCode::usage_error, parsed.error());
    if (parsed->service.empty())
        return fail_with(err, ExitCode::usage_error,
                         make_error(MessageErrorType::InvalidArgument, "the URL names no service (add ?service=NAME)"));

    server::NodeOptions node_options;
    node_options.node_name = "rr.record";
    node_options.threads = 2;
    auto node = server::Node::create(node_options);
    server::gateway::DeviceConfig dc;
    dc.name = cl.device_name.empty() ? parsed->service : cl.device_name;
    dc.url = cl.url;
    dc.username = cl.username;
    dc.password = cl.password;
    dc.token = cl.token;
    dc.http_authorization = http_authorization(cl);
    dc.tls_ca = cl.tls_ca_file;
    dc.tls_certificate = cl.tls_certificate_file;
    dc.tls_private_key = cl.tls_private_key_file;
    dc.backoff_initial = 200ms;
    dc.backoff_max = 2000ms;
    auto device = server::gateway::DeviceMirror::create(node, dc);
    if (!device) {
        node->shutdown();
        return fail_with(err, ExitCode::usage_error, device.error());
    }
    auto shutdown = [&] {
        (*device)->stop();
        node->shutdown();
    };
    (*device)->start();

    // Connected (definitions received) within the timeout, or the device's last reason.
    const auto connect_deadline = Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(cl.timeout_s));
    while ((*device)->status().state != server::gateway::DeviceState::connected && !stop_or_elapsed(stop, connect_deadline))
        std::this_thread::sleep_for(20ms);
    if ((*device)->status().state != server::gateway::DeviceState::connected) {
        const auto reason = (*device)->status().reason;
        shutdown();
        return fail_with(err, ExitCode::connect_failure,
                         make_error(MessageErrorType::ConnectionError,
                                    "not connected to " + cl.url + " within " + std::to_string(static_cast<int>(cl.timeout_s)) +
                                        " s" + (reason.empty() ? "" : ": " + reason)));
    }

    auto api = std::make_shared<server::gateway::JsonApi>(std::vector<std::shared_ptr<server::gateway::DeviceMirror>>{*device});
    server::record::RecordingSpec spec;
    spec.device = dc.name;
    spec.members = cl.record_members;
    if (!cl.encoding.empty()) spec.encodings = {cl.encoding};  // empty: both (the default)
    spec.prefix = cl.prefix;
    // The CLI writes on its user's own computer, where its user chose: --dir is its root (no budget),
    // the files go into it (made new, O_EXCL, as the gateway makes them).
    auto root = std::make_shared<server::record::RecordingsRoot>(cl.directory, 0);
    auto recording = server::record::Recording::start(1, spec, *device, api, root);
    if (!recording) {
        shutdown();
        const auto code = recording.error().type == MessageErrorType::InvalidArgument ? ExitCode::usage_error : ExitCode::rr_error;
        return fail_with(err, code, recording.error());
    }
    // "rr: recording" once the device has answered every wire, pipe and event connection: from that
    // line on, what the device sends is recorded (a script may act on it); --timeout bounds the wait.
    const auto subscribe_deadline =
        Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(cl.timeout_s));
    while ((*recording)->status().connecting > 0 && (*recording)->status().state == server::record::RecordingState::recording &&
           !stop_or_elapsed(stop, subscribe_deadline))
        std::this_thread::sleep_for(20ms);
    {
        auto s = (*recording)->status();
        err << "rr: recording " << dc.name << " (";
        for (std::size_t i = 0; i < s.members.size(); ++i) err << (i ? ", " : "") << s.members[i];
        err << ") to " << (s.files.empty() ? cl.directory : s.files.back());
        if (s.connecting) err << " (" << s.connecting << " not connected yet)";
        err << std::endl;
    }

    const auto end = cl.duration ? Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(*cl.duration))
                                 : Clock::time_point::max();
    while (!stop_or_elapsed(stop, end) && (*recording)->status().state == server::record::RecordingState::recording)
        std::this_thread::sleep_for(20ms);
    (*recording)->stop();
    (*recording)->wait();
    const auto status = (*recording)->status();
    recording->reset();
    shutdown();
    out << server::record::status_json(status).dump() << std::endl;
    if (status.state == server::record::RecordingState::failed) {
        err << "rr: recording failed: " << status.error << std::endl;
        return ExitCode::rr_error;
    }
    return ExitCode::ok;
}

ExitCode run_replay(const CommandLine& cl, std::ostream& out, std::ostream& err, const std::atomic<bool>& stop) {
    server::record::ReplayOptions options;
    options.file = cl.file;
    options.speed = cl.speed;
    options.loop = cl.loop;
    auto replay = server::record::ReplayDevice::open(options);
    if (!replay) return fail_with(err, ExitCode::rr_error, replay.error());

    server::NodeOptions node_options;
    node_options.node_name = "rr.replay";
    node_options.threads = 2;
    auto node = server::Node::create(node_options);
    auto listener = server::open_tcp_listener(node, cl.address, cl.port);
    if (!listener) {
        node->shutdown();
        return fail_with(err, ExitCode::rr_error, listener.error());
    }
    if (auto r = node->register_service((*replay)->service()); !r) {
        node->shutdown();
        return fail_with(err, ExitCode::rr_error, r.error());
    }
    (*replay)->start();
    const std::string host = cl.address.find(':') != std::string::npos ? "[" + cl.address + "]" : cl.address;
    out << "rr+tcp://" << host << ":" << (*listener)->port() << "/?nodeid=" << node->node_id().to_string()
        << "&service=" << (*replay)->name() << std::endl;
    {
        auto s = (*replay)->status();
        err << "rr: replaying " << s.file << " (" << s.object_type << ", " << s.duration_s << " s) as service "
            << s.name << std::endl;
    }

    while (!stop.load()) std::this_thread::sleep_for(20ms);
    const auto status = (*replay)->status();
    (*replay)->stop();
    node->shutdown();
    out << server::record::replay_status_json(status).dump() << std::endl;
    return status.state == "failed" ? ExitCode::rr_error : ExitCode::ok;
}

}  // namespace rr::cli
