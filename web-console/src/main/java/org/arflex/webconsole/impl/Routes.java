package org.arflex.webconsole.impl;

import java.io.IOException;
import java.util.HashMap;
import java.util.Map;

/**
 * The JSON endpoints under {@code api/}: which page backend answers a GET or POST of each. A
 * table is filled while the console activates and only read afterwards; an endpoint two
 * backends claim is a programming error, found at activation.
 */
final class Routes {
    /** One endpoint: reads what it needs from the call and returns the JSON-ready answer. */
    interface Route {
        Object answer(ApiCall call) throws HttpError, IOException;
    }

    private final Map<String, Route> gets = new HashMap<>();
    private final Map<String, Route> posts = new HashMap<>();

    Routes get(String what, Route route) {
        claim(gets, what, route);
        return this;
    }

    /** A state change: {@link ApiCall#refusedCrossSite} has passed before it runs. */
    Routes post(String what, Route route) {
        claim(posts, what, route);
        return this;
    }

    /** Adds every endpoint of {@code more}. */
    Routes add(Routes more) {
        more.gets.forEach((what, route) -> claim(gets, what, route));
        more.posts.forEach((what, route) -> claim(posts, what, route));
        return this;
    }

    Object answerGet(String what, ApiCall call) throws HttpError, IOException {
        return find(gets, what).answer(call);
    }

    Object answerPost(String what, ApiCall call) throws HttpError, IOException {
        return find(posts, what).answer(call);
    }

    private static void claim(Map<String, Route> table, String what, Route route) {
        if (table.putIfAbsent(what, route) != null) {
            throw new IllegalStateException("two backends answer api/" + what);
        }
    }

    private static Route find(Map<String, Route> table, String what) throws HttpError {
        Route r = table.get(what);
        if (r == null) {
            throw new HttpError(404, "no endpoint /api/" + what);
        }
        return r;
    }
}
