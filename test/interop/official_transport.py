"""The official Python client's transport as every test here uses it.

TcpTransport's own connect timeout is 5 s (the official default). Through the gateway a connect is
several round trips and, with `auth: passthrough`, the device's login as well; under CI's load (8 tests
at once on 2 vCPUs beside sanitizer builds) it took longer and `ConnectService` failed with
"Connection timed out". In a test that timeout only bounds a hang, so it is CONNECT_TIMEOUT_S.
"""

CONNECT_TIMEOUT_S = 60


def set_connect_timeout(transport):
    """Gives a TcpTransport (e.g. a node setup's `tcp_transport`) the test's connect timeout."""
    # (milliseconds as an int: the property's setter passes a float, which the binding refuses)
    transport._SetDefaultConnectTimeout(int(CONNECT_TIMEOUT_S * 1000))
    return transport


def client_tcp_transport(RR):
    """A TcpTransport (rr+tcp, rr+ws, rr+wss) of the node singleton with the test's connect timeout;
    the caller registers it."""
    return set_connect_timeout(RR.TcpTransport())
