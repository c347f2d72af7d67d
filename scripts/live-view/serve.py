# A static server with HTTP Range requests and CORS for the screenshots of docs/guide/live-view.md:
# Lichtblick's web build at /, recordings at /files/ (its remote-file source reads a file by
# ranges, which Python's http.server does not serve). Usage: serve.py WEB_BUILD FILES PORT
import os, re, sys, http.server, socketserver
ROOT = sys.argv[1]; FILES = sys.argv[2]; PORT = int(sys.argv[3])
class H(http.server.SimpleHTTPRequestHandler):
    def translate_path(self, path):
        p = path.split('?')[0]
        if p.startswith('/files/'):
            return os.path.join(FILES, p[len('/files/'):])
        return os.path.join(ROOT, p.lstrip('/')) if p != '/' else os.path.join(ROOT, 'index.html')
    def end_headers(self):
        self.send_header('Access-Control-Allow-Origin', '*')
        self.send_header('Access-Control-Allow-Headers', '*')
        self.send_header('Access-Control-Expose-Headers', 'Content-Length, Content-Range, Accept-Ranges')
        self.send_header('Accept-Ranges', 'bytes')
        super().end_headers()
    def do_OPTIONS(self):
        self.send_response(204); self.end_headers()
    def do_GET(self):
        rng = self.headers.get('Range')
        path = self.translate_path(self.path)
        if not rng or not os.path.isfile(path):
            return super().do_GET()
        m = re.match(r'bytes=(\d*)-(\d*)', rng)
        size = os.path.getsize(path)
        start = int(m.group(1)) if m.group(1) else size - int(m.group(2))
        end = int(m.group(2)) if m.group(1) and m.group(2) else size - 1
        end = min(end, size - 1)
        self.send_response(206)
        self.send_header('Content-Type', 'application/octet-stream')
        self.send_header('Content-Range', f'bytes {start}-{end}/{size}')
        self.send_header('Content-Length', str(end - start + 1))
        self.end_headers()
        with open(path, 'rb') as f:
            f.seek(start); self.wfile.write(f.read(end - start + 1))
    def log_message(self, *a): pass
class S(socketserver.ThreadingMixIn, http.server.HTTPServer):
    daemon_threads = True
S(('127.0.0.1', PORT), H).serve_forever()
