"""The getf_param / setf_param of the standard sensor test devices (sensors.py, laser_scanner.py): named
double parameters in memory; each set printed on stdout as {"param_set": name, "value": v} for the test."""

import threading

import numpy as np
import RobotRaconteur as RR


class ParamStore:
    def __init__(self, params, emit):
        self._params = dict(params)
        self._emit = emit
        self._param_lock = threading.Lock()

    def getf_param(self, name):
        with self._param_lock:
            if name not in self._params:
                raise RR.InvalidArgumentException(f"unknown parameter {name}")
            return RR.VarValue(np.array([self._params[name]]), "double[]")

    def setf_param(self, name, value):
        with self._param_lock:
            if name not in self._params:
                raise RR.InvalidArgumentException(f"unknown parameter {name}")
            self._params[name] = float(np.asarray(value.data).reshape(-1)[0])
            v = self._params[name]
        self._emit({"param_set": name, "value": v})
