"""Unit tests of hexcnc_client against a scripted server on a Unix socket (standard library
only): framing, ids, errors, notifications kept aside, split and joined lines, a closed
connection, wait_idle. tests/e2e/python_client.sh also runs the client and the pendant
example against a real `hexcnc machine`."""
import json
import os
import socket
import sys
import tempfile
import threading
import unittest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import hexcnc_client as hc  # noqa: E402


class Server:
    """Accepts one client and answers each request with script(request) -> list of byte
    chunks to send (they may split or join lines)."""

    def __init__(self, script):
        self.dir = tempfile.mkdtemp()
        self.path = os.path.join(self.dir, "s.sock")
        self.lsock = socket.socket(socket.AF_UNIX)
        self.lsock.bind(self.path)
        self.lsock.listen(1)
        self.script = script
        self.requests = []
        self.thread = threading.Thread(target=self._serve, daemon=True)
        self.thread.start()

    def _serve(self):
        conn, _ = self.lsock.accept()
        buf = b""
        with conn:
            while True:
                chunk = conn.recv(65536)
                if not chunk:
                    return
                buf += chunk
                while b"\n" in buf:
                    line, buf = buf.split(b"\n", 1)
                    req = json.loads(line)
                    self.requests.append(req)
                    out = self.script(req)
                    if out is None:
                        return  # close the connection
                    for piece in out:
                        conn.sendall(piece)

    def close(self):
        self.lsock.close()
        try:
            os.unlink(self.path)
        except OSError:
            pass
        os.rmdir(self.dir)


def answer(req, result):
    return (json.dumps({"jsonrpc": "2.0", "id": req["id"], "result": result}) + "\n").encode()


def note(method, params):
    return (json.dumps({"jsonrpc": "2.0", "method": method, "params": params}) + "\n").encode()


class ClientTest(unittest.TestCase):
    def run_with(self, script, fn):
        srv = Server(script)
        try:
            with hc.Client(srv.path, timeout=5) as c:
                return fn(c), srv.requests
        finally:
            srv.close()

    def test_request_framing_and_result(self):
        res, reqs = self.run_with(lambda r: [answer(r, {"echo": r.get("params")})],
                                  lambda c: c.jog("world", "X", 5, distance=10))
        self.assertEqual(res, {"echo": {"frame": "world", "axis": "X", "velocity": 5,
                                        "distance": 10}})
        self.assertEqual(reqs[0]["jsonrpc"], "2.0")
        self.assertEqual(reqs[0]["method"], "jog.move")
        self.assertIsInstance(reqs[0]["id"], int)

    def test_no_params_sends_none(self):
        _, reqs = self.run_with(lambda r: [answer(r, {})], lambda c: c.status())
        self.assertNotIn("params", reqs[0])

    def test_ids_grow_and_match(self):
        def script(r):
            return [answer(r, r["id"])]
        res, reqs = self.run_with(script, lambda c: [c.call("a"), c.call("b"), c.call("c")])
        self.assertEqual(res, [1, 2, 3])
        self.assertEqual([q["id"] for q in reqs], [1, 2, 3])

    def test_error_raises_with_code_and_message(self):
        def script(r):
            return [(json.dumps({"jsonrpc": "2.0", "id": r["id"], "error": {
                "code": -32001, "message": "jog refused: the machine is off"}}) + "\n").encode()]

        def fn(c):
            with self.assertRaises(hc.Error) as cm:
                c.jog("world", "X", 1)
            return cm.exception
        e, _ = self.run_with(script, fn)
        self.assertEqual(e.code, -32001)
        self.assertEqual(e.message, "jog refused: the machine is off")
        self.assertEqual(e.method, "jog.move")

    def test_notifications_before_the_answer_are_kept(self):
        def script(r):
            return [note("message", {"text": "one"}), note("status", {"line": 3}),
                    answer(r, {})]

        def fn(c):
            c.subscribe_messages()
            return [n["method"] for n in c.notifications(timeout=0.2)]
        res, _ = self.run_with(script, fn)
        self.assertEqual(res, ["message", "status"])

    def test_split_and_joined_lines(self):
        def script(r):
            whole = note("message", {"text": "x"}) + answer(r, {"ok": True})
            return [whole[:7], whole[7:30], whole[30:]]
        res, _ = self.run_with(script, lambda c: c.check())
        self.assertEqual(res, {"ok": True})

    def test_closed_connection(self):
        def fn(c):
            with self.assertRaises(EOFError):
                c.status()
        self.run_with(lambda r: None, fn)

    def test_wait_idle_raises_on_fault(self):
        st = {"state": "on", "motion": "fault", "interp": "idle", "homing": False,
              "error": "leg 3: following error 1.2 mm"}

        def fn(c):
            with self.assertRaises(hc.Error) as cm:
                c.wait_idle(timeout=1)
            return cm.exception.message
        msg, _ = self.run_with(lambda r: [answer(r, st)], fn)
        self.assertIn("following error", msg)

    def test_wait_idle_returns_at_rest(self):
        seq = [{"state": "on", "motion": "running", "interp": "reading", "homing": False},
               {"state": "on", "motion": "done", "interp": "idle", "homing": False}]

        def script(r):
            return [answer(r, seq.pop(0) if len(seq) > 1 else seq[0])]
        st, reqs = self.run_with(script, lambda c: c.wait_idle(timeout=5, poll_s=0))
        self.assertEqual(st["motion"], "done")
        self.assertEqual(len(reqs), 2)

    def test_default_socket(self):
        old = os.environ.get("XDG_RUNTIME_DIR")
        try:
            os.environ["XDG_RUNTIME_DIR"] = "/run/user/7"
            self.assertEqual(hc.default_socket(), "/run/user/7/hexcnc.sock")
            del os.environ["XDG_RUNTIME_DIR"]
            self.assertEqual(hc.default_socket(), "/tmp/hexcnc-%d/hexcnc.sock" % os.getuid())
        finally:
            if old is not None:
                os.environ["XDG_RUNTIME_DIR"] = old


if __name__ == "__main__":
    unittest.main()
