//! A headless Chromium driven over the Chrome DevTools protocol (a WebSocket, `tungstenite`):
//! open a page, evaluate script, take screenshots, collect console errors and exceptions.

use base64::Engine;
use serde_json::{json, Value};
use std::io::{BufRead, BufReader};
use std::net::TcpStream;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

type Socket = tungstenite::WebSocket<TcpStream>;

/// The Chromium binary: `$ASP_CHROMIUM`, else `chromium` or `chromium-browser` on the PATH.
fn chromium() -> Option<PathBuf> {
    if let Some(p) = std::env::var_os("ASP_CHROMIUM") {
        let p = PathBuf::from(p);
        return p.is_file().then_some(p);
    }
    let path = std::env::var_os("PATH")?;
    for dir in std::env::split_paths(&path) {
        for name in ["chromium", "chromium-browser"] {
            let candidate = dir.join(name);
            if candidate.is_file() {
                return Some(candidate);
            }
        }
    }
    None
}

/// A PNG screenshot, decoded to RGB.
pub struct Screenshot {
    pub width: u32,
    pub height: u32,
    rgb: Vec<u8>,
}

impl Screenshot {
    pub fn pixel(&self, x: u32, y: u32) -> [u8; 3] {
        let i = ((y * self.width + x) * 3) as usize;
        [self.rgb[i], self.rgb[i + 1], self.rgb[i + 2]]
    }
}

/// One browser with one page; the process is killed on drop.
pub struct Browser {
    child: Child,
    socket: Socket,
    session: String,
    next_id: u64,
    /// Console errors, exceptions and error log entries seen so far.
    errors: Vec<String>,
    _profile: tempfile::TempDir,
}

impl Drop for Browser {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

impl Browser {
    /// Starts Chromium headless, or prints why not and returns `None` when it is not installed.
    pub fn launch() -> Option<Browser> {
        let Some(binary) = chromium() else {
            eprintln!("skipping the browser test: no chromium (not on the PATH, or $ASP_CHROMIUM is not a file); install it with `apt-get install -y chromium`");
            return None;
        };
        let profile = tempfile::tempdir().unwrap();
        let mut child = Command::new(&binary)
            .args([
                "--headless",
                "--no-sandbox",
                "--disable-gpu",
                "--enable-unsafe-swiftshader",
                "--use-angle=swiftshader",
                "--disable-quic",
                "--no-first-run",
                "--disable-background-networking",
                "--disable-component-update",
                "--disable-sync",
                "--disable-extensions",
                "--hide-scrollbars",
                "--window-size=1000,700",
                "--remote-debugging-port=0",
                "--remote-allow-origins=*",
            ])
            .arg(format!("--user-data-dir={}", profile.path().display()))
            .arg("about:blank")
            .stdin(Stdio::null())
            .stdout(Stdio::null())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap_or_else(|e| panic!("{}: cannot start: {e}", binary.display()));
        // "DevTools listening on ws://127.0.0.1:PORT/devtools/browser/ID" on stderr
        let stderr = child.stderr.take().unwrap();
        let (tx, rx) = std::sync::mpsc::channel();
        std::thread::spawn(move || {
            for line in BufReader::new(stderr).lines().map_while(Result::ok) {
                if let Some(url) = line.strip_prefix("DevTools listening on ") {
                    let _ = tx.send(url.trim().to_string());
                }
            }
        });
        let url = match rx.recv_timeout(Duration::from_secs(60)) {
            Ok(url) => url,
            Err(_) => {
                let _ = child.kill();
                panic!("{} did not open its DevTools socket within 60 s", binary.display());
            }
        };
        let host = url.trim_start_matches("ws://").split('/').next().unwrap().to_string();
        let stream = TcpStream::connect(&host).unwrap();
        stream.set_read_timeout(Some(Duration::from_secs(60))).unwrap();
        let (socket, _) = tungstenite::client(url.as_str(), stream).expect("DevTools handshake");
        let mut browser = Browser { child, socket, session: String::new(), next_id: 0, errors: Vec::new(), _profile: profile };
        let target = browser.call(None, "Target.createTarget", json!({ "url": "about:blank" }));
        let target = target["targetId"].as_str().unwrap().to_string();
        let attached = browser.call(None, "Target.attachToTarget", json!({ "targetId": target, "flatten": true }));
        browser.session = attached["sessionId"].as_str().unwrap().to_string();
        let s = Some(browser.session.clone());
        browser.call(s.as_deref(), "Runtime.enable", json!({}));
        browser.call(s.as_deref(), "Log.enable", json!({}));
        browser.call(s.as_deref(), "Page.enable", json!({}));
        browser.call(
            s.as_deref(),
            "Emulation.setDeviceMetricsOverride",
            json!({ "width": 1000, "height": 700, "deviceScaleFactor": 1, "mobile": false }),
        );
        Some(browser)
    }

    /// Sends a command and waits for its answer, collecting errors from the events on the way.
    fn call(&mut self, session: Option<&str>, method: &str, params: Value) -> Value {
        self.next_id += 1;
        let id = self.next_id;
        let mut message = json!({ "id": id, "method": method, "params": params });
        if let Some(s) = session {
            message["sessionId"] = json!(s);
        }
        self.socket.send(tungstenite::Message::text(message.to_string())).expect("send to DevTools");
        loop {
            let msg = self.socket.read().unwrap_or_else(|e| panic!("{method}: no answer from DevTools: {e}"));
            let tungstenite::Message::Text(text) = msg else { continue };
            let v: Value = serde_json::from_str(text.as_str()).unwrap();
            if v["id"].as_u64() == Some(id) {
                if let Some(e) = v.get("error") {
                    panic!("{method}: {e}");
                }
                return v["result"].clone();
            }
            self.note_event(&v);
        }
    }

    fn note_event(&mut self, v: &Value) {
        let p = &v["params"];
        match v["method"].as_str() {
            Some("Runtime.consoleAPICalled") if p["type"] == "error" || p["type"] == "assert" => {
                let args: Vec<String> = p["args"].as_array().into_iter().flatten().map(|a| a["value"].to_string()).collect();
                self.errors.push(format!("console.{}: {}", p["type"].as_str().unwrap_or(""), args.join(" ")));
            }
            Some("Runtime.exceptionThrown") => {
                let d = &p["exceptionDetails"];
                self.errors.push(format!("exception: {} {}", d["text"], d["exception"]["description"]));
            }
            Some("Log.entryAdded") if p["entry"]["level"] == "error" => {
                self.errors.push(format!("log: {} ({})", p["entry"]["text"], p["entry"]["url"]));
            }
            _ => {}
        }
    }

    /// Opens `page` (a file) and waits until the viewer says it is ready.
    pub fn open(&mut self, page: &Path) {
        self.open_until(page, "window.aspViewer !== undefined && window.aspViewer.ready === true");
    }

    /// Opens `page` (a file) and waits until `ready` (a script expression) is true.
    pub fn open_until(&mut self, page: &Path, ready: &str) {
        let url = format!("file://{}", page.canonicalize().unwrap().display());
        let s = self.session.clone();
        self.call(Some(&s), "Page.navigate", json!({ "url": url }));
        self.wait_for(ready, 60.0);
    }

    /// The value of a script expression (promises awaited).
    pub fn eval(&mut self, expression: &str) -> Value {
        let s = self.session.clone();
        let r = self.call(Some(&s), "Runtime.evaluate", json!({ "expression": expression, "returnByValue": true, "awaitPromise": true }));
        if let Some(e) = r.get("exceptionDetails") {
            panic!("{expression}: {e}; errors so far: {:?}", self.errors);
        }
        r["result"]["value"].clone()
    }

    /// Waits until `condition` (a script expression) is true.
    pub fn wait_for(&mut self, condition: &str, seconds: f64) {
        let start = Instant::now();
        loop {
            let s = self.session.clone();
            let r =
                self.call(Some(&s), "Runtime.evaluate", json!({ "expression": format!("Boolean({condition})"), "returnByValue": true }));
            if r["result"]["value"] == true {
                return;
            }
            if start.elapsed().as_secs_f64() > seconds {
                panic!("'{condition}' still false after {seconds} s; errors: {:?}", self.errors);
            }
            std::thread::sleep(Duration::from_millis(100));
        }
    }

    /// A screenshot of the page after the next two animation frames.
    pub fn screenshot(&mut self) -> Screenshot {
        self.eval("new Promise((r) => requestAnimationFrame(() => requestAnimationFrame(() => r(true))))");
        let s = self.session.clone();
        let r = self.call(Some(&s), "Page.captureScreenshot", json!({ "format": "png" }));
        let bytes = base64::engine::general_purpose::STANDARD.decode(r["data"].as_str().unwrap()).unwrap();
        let mut reader = png::Decoder::new(std::io::Cursor::new(bytes)).read_info().unwrap();
        let mut buf = vec![0; reader.output_buffer_size().unwrap()];
        let info = reader.next_frame(&mut buf).unwrap();
        let channels = info.color_type.samples();
        let rgb = buf[..info.buffer_size()].chunks(channels).flat_map(|c| [c[0], c[1], c[2]]).collect();
        Screenshot { width: info.width, height: info.height, rgb }
    }

    /// Fails the test when the page logged an error or threw.
    pub fn assert_no_errors(&mut self) {
        // drain the events that arrived since the last command
        self.eval("true");
        assert!(self.errors.is_empty(), "the page reported errors: {:#?}", self.errors);
    }
}
