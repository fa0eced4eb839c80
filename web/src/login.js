// The login page (web/login.html): POST api/login with a user and password, or a token; the gateway
// answers with an HttpOnly session cookie (the page never sees it) and the dashboard opens.

const form = document.getElementById("login-form");
const error = document.getElementById("login-error");

async function login(body) {
  error.hidden = true;
  try {
    const r = await fetch("api/login", {
      method: "POST",
      headers: { "Content-Type": "application/json", Accept: "application/json" },
      body: JSON.stringify(body),
      cache: "no-store",
    });
    if (r.ok) {
      location.replace("./");
      return;
    }
    let message = `HTTP ${r.status}`;
    try {
      message = (await r.json()).error?.message || message;
    } catch { /* not JSON */ }
    error.textContent = message;
  } catch (e) {
    error.textContent = `gateway unreachable: ${e.message || e}`;
  }
  error.hidden = false;
}

form.addEventListener("submit", (ev) => {
  ev.preventDefault();
  login({ username: form.username.value, password: form.password.value });
});
document.getElementById("login-token-submit").addEventListener("click", () => {
  login({ token: form.token.value.trim() });
});
