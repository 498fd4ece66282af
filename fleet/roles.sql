-- SPDX-License-Identifier: GPL-3.0-or-later
-- roles.sql: the roles and row-level security of the fleet's central
-- PostgreSQL (docs/fleet.md, "Roles"), as they stand at the current central
-- schema version. One source: amfi-sync applies this file (compiled in)
-- once after the last migration it applies, when one of version 8 or later
-- is among them (a migration that adds a table or a view adds their rights
-- here), and it is installed as share/amfi/roles.sql for the owner to read
-- or run again:
--
--     psql -v ON_ERROR_STOP=1 -d fleet -f /usr/share/amfi/roles.sql
--
-- Run as the owner of the tables (who ran 'amfi-sync --init-schema'); it
-- needs CREATEROLE only when amfi_site or amfi_reader does not exist yet.
-- Running it again changes nothing. What it gives:
--   amfi_site    the group of every site's login role: SELECT and INSERT on
--                the site tables, SELECT/INSERT/UPDATE on its marks
--                (fleet_sync_state) and its row of fleet_sites, each bound
--                by row-level security to the rows of the role's own site
--                (fleet_site_roles); no view (a view runs with its owner's
--                rights and would show every site), no DELETE, no UPDATE
--                of shipped rows.
--   amfi_reader  analysts and amfi-report --pg: SELECT on every table and
--                view, every site; writes nothing.
--   the owner    not bound (ENABLE, not FORCE): migrates, creates the
--                sites' roles (amfi-sync --init-site-role), repairs.
-- The site roles themselves are made per site by the owner:
--   amfi-sync --pg 'dbname=fleet' --init-site-role a1-km12
DO $$ BEGIN
  IF NOT EXISTS (SELECT 1 FROM pg_roles WHERE rolname = 'amfi_site') THEN
    CREATE ROLE amfi_site NOLOGIN;
  END IF;
  IF NOT EXISTS (SELECT 1 FROM pg_roles WHERE rolname = 'amfi_reader') THEN
    CREATE ROLE amfi_reader NOLOGIN;
  END IF;
END $$;
-- nobody but the owner and these roles: PUBLIC loses every right
REVOKE ALL ON fleet_migrations, fleet_site_roles, fleet_sync_state, fleet_sites, passages, axles,
  indicators, alerts, baseline, runs, environment, scale_evals, fleet_latest_state,
  fleet_open_alerts, fleet_daily_trend, fleet_passages_daily, fleet_window_trend,
  fleet_latest_scale, fleet_summary FROM PUBLIC;
-- fleet_migrations is written by the owner only
DO $$ DECLARE g text; BEGIN
  FOR g IN SELECT DISTINCT a.grantee::regrole::text
           FROM pg_class AS c, aclexplode(c.relacl) AS a
           WHERE c.oid = 'fleet_migrations'::regclass AND a.grantee <> 0
             AND a.grantee <> c.relowner AND a.privilege_type <> 'SELECT' LOOP
    EXECUTE format('REVOKE INSERT, UPDATE, DELETE, TRUNCATE, REFERENCES, TRIGGER '
                   'ON fleet_migrations FROM %s', g);
  END LOOP;
END $$;
-- the sites
GRANT SELECT ON fleet_migrations, fleet_site_roles TO amfi_site;
GRANT SELECT, INSERT ON passages, axles, indicators, alerts, baseline, runs, environment,
  scale_evals TO amfi_site;
GRANT SELECT, INSERT, UPDATE ON fleet_sync_state, fleet_sites TO amfi_site;
-- the analysts
GRANT SELECT ON fleet_migrations, fleet_site_roles, fleet_sync_state, fleet_sites, passages,
  axles, indicators, alerts, baseline, runs, environment, scale_evals, fleet_latest_state,
  fleet_open_alerts, fleet_daily_trend, fleet_passages_daily, fleet_window_trend,
  fleet_latest_scale, fleet_summary TO amfi_reader;
-- row-level security: a site's role sees and writes its own site's rows
ALTER TABLE fleet_site_roles ENABLE ROW LEVEL SECURITY;
DROP POLICY IF EXISTS fleet_own_role ON fleet_site_roles;
CREATE POLICY fleet_own_role ON fleet_site_roles FOR SELECT TO amfi_site
  USING (role_name = current_user);
DROP POLICY IF EXISTS fleet_reader ON fleet_site_roles;
CREATE POLICY fleet_reader ON fleet_site_roles FOR SELECT TO amfi_reader USING (true);
DO $$ DECLARE t text; BEGIN
  FOREACH t IN ARRAY ARRAY['passages', 'axles', 'indicators', 'alerts', 'baseline', 'runs',
                           'environment', 'scale_evals', 'fleet_sync_state', 'fleet_sites'] LOOP
    EXECUTE format('ALTER TABLE %I ENABLE ROW LEVEL SECURITY', t);
    EXECUTE format('DROP POLICY IF EXISTS fleet_site ON %I', t);
    EXECUTE format('CREATE POLICY fleet_site ON %I TO amfi_site '
      'USING (site_id = (SELECT r.site_id FROM fleet_site_roles AS r '
      'WHERE r.role_name = current_user)) '
      'WITH CHECK (site_id = (SELECT r.site_id FROM fleet_site_roles AS r '
      'WHERE r.role_name = current_user))', t);
    EXECUTE format('DROP POLICY IF EXISTS fleet_reader ON %I', t);
    EXECUTE format('CREATE POLICY fleet_reader ON %I FOR SELECT TO amfi_reader USING (true)', t);
  END LOOP;
END $$;
