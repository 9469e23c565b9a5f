package org.arflex.contract;

import static org.arflex.contract.ContractValidator.SHA256;

import java.net.URI;
import java.net.URISyntaxException;
import java.util.Locale;
import java.util.Optional;
import org.arflex.contract.internal.ContractXml;

/**
 * SPEC §12: checks a contract's {@code <update>} (URL scheme, host or path, no credentials, SHA-256);
 * called by {@link ContractValidator}, reports into its {@link Problems}.
 */
final class UpdateValidation {
    private UpdateValidation() {
    }

    static Optional<UpdateSpec> check(Problems p, ContractXml.Update u) {
        boolean ok = true;
        URI uri = null;
        if (u.url == null) {
            p.at(u, "12", "update/@url", "required attribute is missing");
            ok = false;
        } else {
            try {
                uri = new URI(u.url);
                String scheme = uri.getScheme() == null ? "" : uri.getScheme().toLowerCase(Locale.ROOT);
                if (!scheme.equals("https") && !scheme.equals("file")) {
                    p.at(u, "12", "update/@url", "scheme '" + (uri.getScheme() == null ? "" : uri.getScheme())
                            + "' is not allowed; only https and file URLs");
                    ok = false;
                } else if (scheme.equals("https") && (uri.getHost() == null || uri.getHost().isEmpty())) {
                    p.at(u, "12", "update/@url", "an https URL needs a host");
                    ok = false;
                } else if (scheme.equals("file") && (uri.getPath() == null || !uri.getPath().startsWith("/"))) {
                    p.at(u, "12", "update/@url", "a file URL needs an absolute path (file:/path/x.jar)");
                    ok = false;
                } else if (uri.getUserInfo() != null) {
                    p.at(u, "12", "update/@url", "credentials in the URL are not allowed");
                    ok = false;
                }
            } catch (URISyntaxException e) {
                p.at(u, "12", "update/@url", "'" + u.url + "' is not a URL: " + e.getReason());
                ok = false;
            }
        }
        if (u.sha256 == null) {
            p.at(u, "12", "update/@sha256", "required attribute is missing (64 hex digits)");
            ok = false;
        } else if (!SHA256.matcher(u.sha256).matches()) {
            p.at(u, "12", "update/@sha256", "'" + u.sha256 + "' is not a SHA-256 (exactly 64 hex digits)");
            ok = false;
        }
        return ok ? Optional.of(new UpdateSpec(uri, u.sha256.toLowerCase(Locale.ROOT))) : Optional.empty();
    }
}
