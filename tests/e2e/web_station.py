"""web_station.py: the operator's station (`hexcnc web`) in headless Chromium, driven by
Selenium as an operator would, against `hexcnc machine` on the simulated clock: the page
loads without console errors and draws the machine; e-stop reset, power, homing; an
incremental jog and an MDI move seen on the DRO; the paper's program opened, checked, run,
paused, resumed and finished at its pose; a fault shown with its cause; a second browser that
watches and cannot command; the bridge's refusals (methods, paths); and on an address other
than loopback, a missing or wrong token refused. Screenshots go to $HEXCNC_SCREENSHOTS
(default: a temporary folder)."""
import json
import os
import re
import shutil
import socket
import subprocess
import sys
import tempfile
import time
import urllib.request

from selenium import webdriver
from selenium.webdriver.chrome.service import Service
from selenium.webdriver.common.action_chains import ActionChains
from selenium.webdriver.common.by import By
from selenium.webdriver.support.ui import Select

ROOT = os.path.abspath(os.environ.get("HEXCNC_ROOT", os.path.join(os.path.dirname(__file__), "..", "..")))
BIN = os.environ.get("HEXCNC_BIN", os.path.join(ROOT, "bin", "hexcnc"))
FAILS = []
PROCS = []
DRIVERS = []


def check(name, cond, detail=""):
    print(("ok   " if cond else "FAIL ") + name + ("" if cond else "  " + str(detail)[:600]))
    if not cond:
        FAILS.append(name)
    return cond


def wait_until(fn, timeout=30.0, step=0.05):
    end = time.time() + timeout
    last = None
    while time.time() < end:
        try:
            last = fn()
            if last:
                return last
        except Exception as e:  # an element not there yet
            last = e
        time.sleep(step)
    return None


def free_port():
    """A free loopback port below the kernel's ephemeral range: a port from bind(0) is an
    ephemeral one, which an outgoing connection (the browser's, anything's) may be given
    before the station binds it (tests/test_net_util.h does the same for the C tests)."""
    low = 32768
    try:
        with open("/proc/sys/net/ipv4/ip_local_port_range") as f:
            low = int(f.read().split()[0])
    except (OSError, ValueError, IndexError):
        pass
    first = 10000
    span = min(low, 20000) - first     # the Modbus shell tests take 20000 .. 32000
    start = first + (os.getpid() * 7919 + int(time.time())) % span
    for i in range(span):
        p = first + (start - first + i) % span
        s = socket.socket()
        try:
            s.bind(("127.0.0.1", p))
            return p
        except OSError:
            continue
        finally:
            s.close()
    raise RuntimeError("no free port in %d .. %d" % (first, first + span - 1))


def session_call(sock, method, **params):
    """One call straight to the session's socket (the test's own hand, not the page's)."""
    s = socket.socket(socket.AF_UNIX)
    s.settimeout(30)
    s.connect(sock)
    s.sendall(json.dumps({"jsonrpc": "2.0", "id": 1, "method": method, "params": params}).encode() + b"\n")
    buf = b""
    while True:
        buf += s.recv(1 << 16)
        for line in buf.split(b"\n")[:-1]:
            m = json.loads(line)
            if m.get("id") == 1:
                s.close()
                return m
    

class MessageListener:
    """A client of the session of its own, subscribed to its messages."""

    def __init__(self, sock):
        self.s = socket.socket(socket.AF_UNIX)
        self.s.connect(sock)
        self.s.sendall(b'{"jsonrpc":"2.0","id":1,"method":"messages.subscribe"}\n')
        self.s.setblocking(False)
        self.buf, self.seen = b"", []

    def read(self):
        try:
            while True:
                chunk = self.s.recv(1 << 16)
                if not chunk:
                    break
                self.buf += chunk
        except BlockingIOError:
            pass
        *lines, self.buf = self.buf.split(b"\n")
        for line in lines:
            m = json.loads(line)
            if m.get("method") == "message":
                self.seen.append(m["params"]["text"])
        return self.seen

    def close(self):
        self.s.close()


def settled(read, hold=0.5, timeout=20):
    """Waits until read() stays the same for `hold` seconds."""
    end = time.time() + timeout
    last, since = read(), time.time()
    while time.time() < end:
        time.sleep(0.05)
        v = read()
        if v != last:
            last, since = v, time.time()
        elif time.time() - since >= hold:
            return True
    return False


def browser():
    o = webdriver.ChromeOptions()
    for a in ("--headless=new", "--no-sandbox", "--window-size=1366,768", "--use-angle=swiftshader",
              "--enable-unsafe-swiftshader", "--disable-dev-shm-usage"):
        o.add_argument(a)
    o.set_capability("goog:loggingPrefs", {"browser": "ALL"})
    d = webdriver.Chrome(service=Service("/usr/bin/chromedriver"), options=o)
    DRIVERS.append(d)
    return d


def tid(d, name):
    return d.find_element(By.CSS_SELECTOR, '[data-testid="%s"]' % name)


def text(d, name):
    return tid(d, name).text


def dro(d, axis):
    return float(text(d, "dro-" + axis))


def tab(d, name):
    d.find_element(By.CSS_SELECTOR, '.tabs button[data-tab="%s"]' % name).click()


def console_errors(d):
    return [e["message"] for e in d.get_log("browser") if e["level"] == "SEVERE"]


def canvas_pixels(d):
    """Pixels of the 3-D view that differ from its background colour, out of how many."""
    return d.execute_script("""
        const c = document.querySelector('[data-testid=view3d]');
        const o = document.createElement('canvas'); o.width = c.width; o.height = c.height;
        const g = o.getContext('2d'); g.drawImage(c, 0, 0);
        const px = g.getImageData(0, 0, o.width, o.height).data;
        let n = 0;
        for (let i = 0; i < px.length; i += 4)
            if (Math.abs(px[i] - 15) + Math.abs(px[i + 1] - 18) + Math.abs(px[i + 2] - 21) > 24) n++;
        return [n, px.length / 4];""")


def raw_ws(d, messages):
    """Sends messages on a WebSocket of the page's own and returns the answers."""
    return d.execute_async_script("""
        const msgs = arguments[0], done = arguments[arguments.length - 1];
        const ws = new WebSocket('ws://' + location.host + '/ws');
        const out = [];
        ws.onopen = () => msgs.forEach((m) => ws.send(JSON.stringify(m)));
        ws.onmessage = (e) => { const m = JSON.parse(e.data);
            if (m.id !== undefined) { out.push(m); if (out.length === msgs.length) { ws.close(); done(out); } } };
        ws.onerror = () => done(['error']);
        setTimeout(() => done(out), 10000);""", messages)


def start(args, **kw):
    p = subprocess.Popen(args, **kw)
    PROCS.append(p)
    return p


def wait_http(url, proc, timeout=10):
    def up():
        if proc.poll() is not None:
            raise SystemExit("the station exited with %d" % proc.returncode)
        try:
            return urllib.request.urlopen(url, timeout=1).status == 200
        except OSError:
            return False
    return wait_until(up, timeout)


def make_config(tmp):
    cfg = os.path.join(tmp, "cfg")
    shutil.copytree(os.path.join(ROOT, "configs", "sim"), cfg)
    os.mkdir(os.path.join(cfg, "progs"))
    shutil.copy(os.path.join(ROOT, "examples", "paper", "prog10_g141_d20.ngc"), os.path.join(cfg, "progs"))
    ini = os.path.join(cfg, "tmu-hexapod.ini")
    with open(ini) as f:
        text_ = f.read()
    text_ = text_.replace("[DISPLAY]\n", "[DISPLAY]\nPROGRAM_PREFIX = progs\n", 1)
    with open(ini, "w") as f:
        f.write(text_)
    return ini


def main(tmp, shots):
    ini = make_config(tmp)
    sock = os.path.join(tmp, "m.sock")
    start([BIN, "machine", "--sim-clock", "--quiet", "--socket", sock, ini])
    if not wait_until(lambda: os.path.exists(sock), 20):
        return check("the session starts", False)
    port = free_port()
    url = "http://127.0.0.1:%d/" % port
    web = start([BIN, "web", "--quiet", "--listen", "127.0.0.1:%d" % port, "--socket", sock, ini])
    check("the station serves the page", wait_http(url, web))

    a = browser()
    a.get(url)
    check("the page connects and shows the state: estop",
          wait_until(lambda: text(a, "state").startswith("estop")), text(a, "state"))
    px = wait_until(lambda: (lambda n: n if n[0] > 0.02 * n[1] else None)(canvas_pixels(a)), 10)
    check("the 3-D view draws the machine (over 2 % of its pixels differ from the background)",
          px, canvas_pixels(a))
    a.save_screenshot(os.path.join(shots, "station-estop.png"))

    # a second browser watches
    b = browser()
    b.get(url)
    check("a second browser sees the same state", wait_until(lambda: text(b, "state").startswith("estop")))

    tid(a, "take-control").click()
    check("take control", wait_until(lambda: a.find_element(By.ID, "control-state").text == "in control"))
    tid(a, "estop").click()
    check("e-stop reset: state off", wait_until(lambda: text(a, "state").startswith("off")), text(a, "state"))
    tid(b, "power").click()
    check("the watching browser cannot switch the machine on (told why)",
          wait_until(lambda: "control" in text(b, "messages") and "power" in text(b, "messages")),
          text(b, "messages"))
    time.sleep(0.3)
    check("... and the machine stays off", text(a, "state").startswith("off"), text(a, "state"))
    tid(a, "power").click()
    check("power on: state on", wait_until(lambda: text(a, "state").startswith("on")), text(a, "state"))
    tid(a, "home").click()
    homed = wait_until(lambda: re.search(r"homed$", a.find_element(By.ID, "modal").text, re.M) and
                       "homing" not in text(a, "state") and abs(dro(a, "Z") - 645) < 1e-3, 60)
    check("home: every leg homed, the platform at HOME (Z 645 on the DRO)", homed,
          (text(a, "state"), a.find_element(By.ID, "modal").text))
    check("leg rows show lengths", re.search(r"\d+\.\d\d", text(a, "leg-1")), text(a, "leg-1"))

    # incremental jog
    Select(tid(a, "jog-step")).select_by_value("1")
    x0 = dro(a, "X")
    tid(a, "jog-X+").click()
    check("jog X+ by 1 mm: the DRO shows X + 1.000",
          wait_until(lambda: abs(dro(a, "X") - (x0 + 1)) < 5e-4 and "idle" not in text(a, "state") or
                     abs(dro(a, "X") - (x0 + 1)) < 5e-4, 20), (x0, text(a, "dro-X")))
    check("the watching browser's DRO follows", wait_until(lambda: abs(dro(b, "X") - (x0 + 1)) < 5e-4))

    # continuous jog: held, it moves; released, it stops
    Select(tid(a, "jog-step")).select_by_value("0")
    sp = a.find_element(By.ID, "jog-speed")
    sp.clear()
    sp.send_keys("0.2")
    y0 = dro(a, "Y")
    ActionChains(a).click_and_hold(tid(a, "jog-Y+")).perform()
    moved = wait_until(lambda: dro(a, "Y") > y0 + 0.01, 20)
    ActionChains(a).release().perform()
    check("continuous jog Y+: moves while the button is held", moved, (y0, text(a, "dro-Y")))
    check("... and stops when it is released", settled(lambda: dro(a, "Y")), text(a, "dro-Y"))
    # held while the connection is lost (the station's process dies): the session stops the
    # jog of the client it lost. (A page that is closed or reloaded stops its jog itself.)
    listener = MessageListener(sock)
    ActionChains(a).click_and_hold(tid(a, "jog-Y-")).perform()
    wait_until(lambda: session_call(sock, "status.get")["result"]["motion"] == "jogging", 10)
    web.kill()
    web.wait()
    said = wait_until(lambda: any("disconnected during a continuous jog" in m for m in listener.read()), 10)
    check("a continuous jog whose page is gone is stopped by the session, which says why", said,
          listener.seen)
    check("... and the machine comes to rest",
          wait_until(lambda: session_call(sock, "status.get")["result"]["motion"] != "jogging", 10),
          session_call(sock, "status.get")["result"]["motion"])
    listener.close()
    check("the page says the connection is lost", wait_until(
        lambda: "disconnected" in a.find_element(By.ID, "conn").text, 10))
    web = start([BIN, "web", "--quiet", "--listen", "127.0.0.1:%d" % port, "--socket", sock, ini])
    check("the station back: the page connects again by itself",
          wait_until(lambda: a.find_element(By.ID, "conn").text == "connected", 20))
    ActionChains(a).release().perform()
    a.get_log("browser")   # the refused reconnections of the outage are not the page's errors
    wait_until(lambda: text(a, "state").startswith("on"))
    tid(a, "take-control").click()
    check("(control taken again)", wait_until(lambda: a.find_element(By.ID, "control-state").text ==
                                              "in control"))

    # MDI
    tab(a, "mdi")
    tid(a, "mdi-input").send_keys("G0 X10 Y5")
    tid(a, "mdi-send").click()
    check("MDI G0 X10 Y5: the DRO shows X 10.000 Y 5.000",
          wait_until(lambda: abs(dro(a, "X") - 10) < 5e-4 and abs(dro(a, "Y") - 5) < 5e-4, 30),
          (text(a, "dro-X"), text(a, "dro-Y")))
    check("MDI history keeps the line", "G0 X10 Y5" in a.find_element(By.ID, "mdi-history").text)
    a.save_screenshot(os.path.join(shots, "station-mdi.png"))

    # the paper's program: open, check, run, pause, resume, finish
    tab(a, "program")
    wait_until(lambda: Select(a.find_element(By.ID, "program-file")).options)
    Select(a.find_element(By.ID, "program-file")).select_by_value("prog10_g141_d20.ngc")
    tid(a, "program-open").click()
    check("the program opens (name and line count shown)",
          wait_until(lambda: "prog10_g141_d20.ngc (14 lines)" in a.find_element(By.ID, "program-name").text),
          a.find_element(By.ID, "program-name").text)
    check("the listing shows the program", wait_until(lambda: "G141 X50 Y-80" in a.find_element(By.ID, "listing").text))
    tid(a, "check").click()
    rep = wait_until(lambda: "Check passed" in text(a, "check-report") and text(a, "check-report"), 60)
    check("the check's report: passed, with time and length", rep, text(a, "check-report"))
    a.save_screenshot(os.path.join(shots, "station-program.png"))
    a.execute_script("""const s = document.querySelector('[data-testid=feed-override]');
        s.focus(); s.value = '10'; s.dispatchEvent(new Event('input')); s.blur();""")
    tid(a, "run").click()
    check("run: the program runs (a line > 0, reading)",
          wait_until(lambda: int(text(a, "line")) > 0 and "reading" in text(a, "state"), 30),
          (text(a, "line"), text(a, "state")))
    tid(a, "pause").click()
    check("pause: the state says paused", wait_until(lambda: "paused" in text(a, "state"), 20), text(a, "state"))
    wait_until(lambda: "motion paused" in a.find_element(By.ID, "modal").text, 20)
    held = [dro(a, k) for k in "XYZ"]
    time.sleep(0.6)
    check("paused: the DRO holds still", held == [dro(a, k) for k in "XYZ"], (held, [dro(a, k) for k in "XYZ"]))
    a.save_screenshot(os.path.join(shots, "station-paused.png"))
    a.execute_script("""const s = document.querySelector('[data-testid=feed-override]');
        s.focus(); s.value = '200'; s.dispatchEvent(new Event('input')); s.blur();""")
    tid(a, "resume").click()
    # 80 min of machine time at 200 %: the simulated clock runs it in about 20 s
    end = wait_until(lambda: "program finished" in text(a, "messages") and
                     not re.search("reading|paused|waiting", text(a, "state")), 180)
    check("resume: the program runs to its end", end, text(a, "state"))
    # the compensated end of the paper's path (examples/paper/prog10_g141_d20.ngc's header)
    want = {"X": 59.975641, "Y": -20.0, "Z": 630.697565, "A": 0.0, "B": -4.0, "C": 0.0}
    got = {k: dro(a, k) for k in want}
    check("it ends at the compensated end pose X59.976 Y-20 Z630.698 B-4 (DRO within 0.002)",
          all(abs(got[k] - want[k]) < 2e-3 for k in want), got)
    msgs = text(a, "messages")
    check("messages tell of the program's start and end", "finished" in msgs or "ended" in msgs, msgs[:400])

    # the tool table editor: a wear value saved through the page reaches the table
    tab(a, "tools")
    rows = wait_until(lambda: a.find_elements(By.CSS_SELECTOR, "#tools tbody tr"), 10)
    check("the tool table is listed", rows)
    if rows:
        inputs = rows[0].find_elements(By.TAG_NAME, "input")
        tool = int(inputs[0].get_attribute("value"))
        inputs[4].clear()
        inputs[4].send_keys("-0.03")
        rows[0].find_element(By.TAG_NAME, "button").click()
        saved = wait_until(lambda: [t for t in session_call(sock, "tooltable.get")["result"]["tools"]
                                    if t["tool"] == tool and abs(t["wear"] + 0.03) < 1e-9], 10)
        check("a tool's wear edited on the page is saved in the table (T%d wear -0.03)" % tool,
              saved, session_call(sock, "tooltable.get")["result"]["tools"][:3])
    tab(a, "program")

    # hostile requests through the page's own WebSocket
    r = raw_ws(a, [{"jsonrpc": "2.0", "id": 1, "method": "machine.shutdown"},
                   {"jsonrpc": "2.0", "id": 2, "method": "program.open", "params": {"path": "../tmu-hexapod.ini"}},
                   {"jsonrpc": "2.0", "id": 3, "method": "program.lines", "params": {"path": "/etc/passwd", "from": 1, "count": 5}}])
    codes = {m["id"]: m.get("error", {}).get("code") for m in r if isinstance(m, dict)}
    check("the bridge refuses machine.shutdown (-32601), a path out of the program folder and an "
          "absolute one (-32004)", codes == {1: -32601, 2: -32004, 3: -32004}, r)

    # a fault from outside: the e-stop chain's fault input, set by another client of the
    # session (the page gives control up for it: commands need control or nobody holding it)
    tid(a, "take-control").click()
    check("(control given up)", wait_until(lambda: a.find_element(By.ID, "control-state").text ==
                                           "watching"))
    r = session_call(sock, "hal.set", name="estop-latch.0.fault-in", value=True)
    check("(the fault input is set)", "result" in r, r)
    check("a fault: the page shows e-stop and the fault's cause",
          wait_until(lambda: text(a, "state").startswith("estop") and
                     a.find_element(By.ID, "fault").is_displayed() and
                     len(a.find_element(By.ID, "fault").text) > 20, 20),
          (text(a, "state"), a.find_element(By.ID, "fault").text, text(a, "messages")[:300]))
    print("     fault shown: %s" % a.find_element(By.ID, "fault").text)
    a.save_screenshot(os.path.join(shots, "station-fault.png"))
    session_call(sock, "hal.set", name="estop-latch.0.fault-in", value=False)
    tid(a, "take-control").click()
    check("(control taken again)", wait_until(lambda: a.find_element(By.ID, "control-state").text ==
                                              "in control"))
    tid(a, "estop").click()
    check("after the fault, e-stop reset: state off", wait_until(lambda: text(a, "state").startswith("off"), 20),
          text(a, "state"))

    errs = console_errors(a) + console_errors(b)
    check("no console errors in either browser", not errs, errs)
    a.set_window_size(1024, 768)
    tab(a, "manual")
    time.sleep(0.5)
    a.save_screenshot(os.path.join(shots, "station-tablet.png"))
    check("a 1024 px wide screen still shows the DRO and the e-stop",
          tid(a, "dro-X").is_displayed() and tid(a, "estop").is_displayed())

    # an address other than loopback: without a token the station does not start
    port2 = free_port()
    p = subprocess.run([BIN, "web", "--listen", "0.0.0.0:%d" % port2, "--socket", sock, ini],
                       capture_output=True, text=True, timeout=20)
    check("0.0.0.0 without [API] TOKEN_FILE: refused to start, naming the key",
          p.returncode == 1 and "TOKEN_FILE" in p.stderr, (p.returncode, p.stderr))
    tok = os.path.join(os.path.dirname(ini), "token")
    with open(tok, "w") as f:
        f.write("s3cret-token-for-the-test-0123\n")
    os.chmod(tok, 0o644)
    with open(ini) as f:
        t = f.read()
    with open(ini, "w") as f:
        f.write(t.replace("[API]\n", "[API]\nTOKEN_FILE = token\n", 1) if "[API]\n" in t
                else t + "\n[API]\nTOKEN_FILE = token\n")
    p = subprocess.run([BIN, "web", "--listen", "0.0.0.0:%d" % port2, "--socket", sock, ini],
                       capture_output=True, text=True, timeout=20)
    check("a token file others may read is refused", p.returncode == 1 and "chmod 600" in p.stderr, p.stderr)
    os.chmod(tok, 0o600)
    web2 = start([BIN, "web", "--quiet", "--listen", "0.0.0.0:%d" % port2, "--socket", sock, ini])
    url2 = "http://127.0.0.1:%d/" % port2
    check("with a token the station serves on 0.0.0.0", wait_http(url2, web2))
    c = browser()
    for label, q in (("no token", ""), ("a wrong token", "?token=wrong-token-0123456789")):
        c.get(url2 + q)
        check("%s: the WebSocket is refused and the page says so" % label,
              wait_until(lambda: "disconnected" in c.find_element(By.ID, "conn").text and
                         "refused" in text(c, "messages"), 15),
              (c.find_element(By.ID, "conn").text, text(c, "messages")[:200]))
        check("%s: no machine state reaches the page" % label, text(c, "state") == "estop" and
              text(c, "dro-X") == "—", (text(c, "state"), text(c, "dro-X")))
    c.get(url2 + "?token=s3cret-token-for-the-test-0123")
    check("the right token: connected, the state shown",
          wait_until(lambda: c.find_element(By.ID, "conn").text == "connected" and
                     text(c, "state").startswith("off"), 15), (c.find_element(By.ID, "conn").text, text(c, "state")))
    check("the token leaves the address bar", "token" not in c.current_url, c.current_url)


def cleanup():
    for d in DRIVERS:
        try:
            d.quit()
        except Exception:
            pass
    for p in PROCS:
        if p.poll() is None:
            p.terminate()
            try:
                p.wait(10)
            except subprocess.TimeoutExpired:
                p.kill()


if __name__ == "__main__":
    tmp = tempfile.mkdtemp(prefix="hexcnc-web-")
    shots = os.environ.get("HEXCNC_SCREENSHOTS") or os.path.join(tmp, "shots")
    os.makedirs(shots, exist_ok=True)
    try:
        main(tmp, shots)
    except Exception as e:
        import traceback
        traceback.print_exc()
        check("the test ran to its end", False, e)
    finally:
        cleanup()
        shutil.rmtree(tmp, ignore_errors=True)
    print("screenshots in %s" % shots)
    print("web_station: %d failed" % len(FAILS))
    sys.exit(1 if FAILS else 0)
