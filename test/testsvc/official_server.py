#!/usr/bin/env python3
"""The official test server of a checkout of robotraconteur/robotraconteur (its
test/python/RobotRaconteurTest/test_server.py, the four test services on the official Python library)
as a child process for official_suite.py: the reference the suite's results against rr-test-service
are compared with, on the same transports and behind the same gateway.

    .venv/bin/python test/testsvc/official_server.py --repo DIR --nodename NAME

The official program listens on the fixed port 22223 as node `py_testprog` and waits for a line on
stdin; here its ServerNodeSetup is given port 0 and NAME instead (so that runs do not collide), and it
prints one line `ready {"url", "ws_url", "local_url", "port", "nodename"}` (rr-test-service's ready line)
when its services are registered, then runs until SIGTERM or SIGINT (exit 0). Its first service also
gets the two service attributes that the suite's own in-process server sets (test_attributes reads
them). Nothing of the official program is copied: it is imported from the checkout and run as it is.
"""

import argparse
import json
import os
import signal
import sys


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--repo", required=True)
    ap.add_argument("--nodename", required=True)
    args = ap.parse_args()
    sys.path.insert(0, os.path.join(args.repo, "test", "python"))

    import RobotRaconteur as RR
    from RobotRaconteurTest import test_server

    setups = []
    original_setup = RR.ServerNodeSetup

    def server_node_setup(nodename, port, *a, **kw):
        s = original_setup(args.nodename, 0, *a, **kw)
        setups.append(s)
        return s

    def serve_until_signal(prompt=""):
        port = setups[0].tcp_transport.GetListenPort()
        print("ready " + json.dumps({"url": "rr+tcp://127.0.0.1:%d/" % port, "ws_url": "rr+ws://127.0.0.1:%d/" % port,
                                     "local_url": "rr+local:///?nodename=" + args.nodename, "port": port,
                                     "nodename": args.nodename}), flush=True)
        signal.sigwait({signal.SIGTERM, signal.SIGINT})

    # The suite's own in-process server (service_test_util.TestServerNodeConfig) gives the first
    # service two attributes that test_server.py does not; test_attributes reads them.
    original_register = RR.RobotRaconteurNode.RegisterService

    def register_service(node, name, *a, **kw):
        context = original_register(node, name, *a, **kw)
        if name == "RobotRaconteurTestService":
            context.SetServiceAttributes({"test": RR.VarValue("This is a test attribute", "string"),
                                          "test2": RR.VarValue(42, "int32")})
        return context

    signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGTERM, signal.SIGINT})
    RR.RobotRaconteurNode.RegisterService = register_service
    RR.ServerNodeSetup = server_node_setup
    test_server.raw_input = serve_until_signal
    test_server.main()
    return 0


if __name__ == "__main__":
    sys.exit(main())
