package org.arflex.drcr.impl.services;

import java.util.List;
import org.arflex.drcr.dto.ChangeSetDTO;
import org.arflex.drcr.impl.runtime.ChangeSetResult;

/** The service's answers (D35): the cell's result as a DTO, or a refusal before the cell was asked. */
final class ChangeSetAnswers {

    private ChangeSetAnswers() {
    }

    static ChangeSetDTO dto(List<String> actions, ChangeSetResult r) {
        ChangeSetDTO d = new ChangeSetDTO();
        d.actions = actions.toArray(String[]::new);
        d.admitted = r.admitted();
        d.applied = r.applied();
        d.refusal = r.refusal();
        d.text = r.text();
        d.prepareMs = r.prepareMs();
        d.switchUs = r.switchUs();
        return d;
    }

    static ChangeSetDTO refused(List<String> actions, String why) {
        ChangeSetDTO d = new ChangeSetDTO();
        d.actions = actions.toArray(String[]::new);
        d.refusal = why;
        d.text = "change set: " + String.join("; ", actions) + "\nrefused: " + why + "\n";
        return d;
    }
}
