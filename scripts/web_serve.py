"""Serves web/dist/ on localhost, as a static host would: a file with a gzip twin beside it
(`trainer_bg.wasm.gz`) goes out compressed to a browser that accepts gzip, and WebAssembly
with its own media type. Usage: python3 scripts/web_serve.py [PORT] [FOLDER]"""

import functools
import http.server
import os
import sys


class Handler(http.server.SimpleHTTPRequestHandler):
    extensions_map = {
        **http.server.SimpleHTTPRequestHandler.extensions_map,
        ".wasm": "application/wasm",
        ".js": "text/javascript",
    }

    def send_head(self):
        path = self.translate_path(self.path)
        twin = path + ".gz"
        accepts = "gzip" in self.headers.get("Accept-Encoding", "")
        if not (accepts and os.path.isfile(path) and os.path.isfile(twin)):
            return super().send_head()
        body = open(twin, "rb")
        self.send_response(200)
        self.send_header("Content-Type", self.guess_type(path))
        self.send_header("Content-Encoding", "gzip")
        self.send_header("Content-Length", str(os.fstat(body.fileno()).st_size))
        self.send_header("Last-Modified", self.date_time_string(int(os.path.getmtime(twin))))
        self.end_headers()
        return body

    def log_message(self, format, *args):
        pass


def main():
    port = int(sys.argv[1]) if len(sys.argv) > 1 else 8080
    folder = sys.argv[2] if len(sys.argv) > 2 else "web/dist"
    handler = functools.partial(Handler, directory=folder)
    with http.server.ThreadingHTTPServer(("127.0.0.1", port), handler) as server:
        print(f"the trainer: http://localhost:{port}/ (?scenario=STEM picks a shipped scenario)")
        server.serve_forever()


if __name__ == "__main__":
    main()
